// The geometry of the check by eye (paper Sec. 9.2, Figs. 23 and 26): frames, bearings,
// odometry between two times, the corners of a scan and the corner-to-line offsets.
#include <algorithm>
#include <cmath>
#include <limits>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/pipeline/reprojection.hpp"

namespace omnivert::pipeline {

Eigen::Vector2d transform_point(const Pose2d& pose, const Eigen::Vector2d& p) {
  const double c = std::cos(pose.z()), s = std::sin(pose.z());
  return {pose.x() + c * p.x() - s * p.y(), pose.y() + s * p.x() + c * p.y()};
}

Pose2d compose(const Pose2d& a, const Pose2d& b) {
  const Eigen::Vector2d t = transform_point(a, b.head<2>());
  return {t.x(), t.y(), wrap_angle(a.z() + b.z())};
}

Pose2d inverse(const Pose2d& a) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  return {-c * a.x() - s * a.y(), s * a.x() - c * a.y(), wrap_angle(-a.z())};
}

double camera_bearing(const calib::Extrinsics& x, const Eigen::Vector2d& p_robot) {
  // Conventions (docs/theory/conventions.md, Fig. 19): T_base_cam = [Rz(phi + psi) | rho
  // (cos phi, sin phi)]; the bearing is the point's direction in the camera frame.
  const Pose2d cam(x.rho * std::cos(x.phi), x.rho * std::sin(x.phi), x.phi + x.psi);
  const Eigen::Vector2d q = transform_point(inverse(cam), p_robot);
  return std::atan2(q.y(), q.x());
}

Pose2d odometry_between(const dataset::Dataset& data, std::int64_t t_a, std::int64_t t_b) {
  if (t_b < t_a) return inverse(odometry_between(data, t_b, t_a));
  std::vector<Eigen::Vector2d> travel;
  auto push = [&](const dataset::WheelTravel& w) { travel.emplace_back(w.left, w.right); };
  push(data.travel_at(t_a));
  for (const dataset::WheelRecord& w : data.wheel())
    if (w.timestamp_ns > t_a && w.timestamp_ns < t_b) push(w.travel);
  push(data.travel_at(t_b));
  const double e = data.wheel_sensor().wheel_base;
  // Eq. (14) over each sample step, composed (calib::compose_wheel_steps).
  const Eigen::Vector3d step = calib::compose_wheel_steps(travel, e);
  return calib::integrate_pose_lateral(Eigen::Vector3d::Zero(), step(0), step(1), step(2), e);
}

namespace {

struct Ray {
  int k = 0;  // index in the scan
  Eigen::Vector2d p;
  double r = 0;
};

// A straight piece of a run: rays [a, b] (indices into the run), its fitted line.
struct Piece {
  int a = 0, b = 0;
  Eigen::Vector2d c, d;  // a point of the line, its unit direction
  bool good = false;
};

double distance_to_chord(const Eigen::Vector2d& p,
                         const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d u = b - a;
  const double n = u.norm();
  if (n < 1e-12) return (p - a).norm();
  return std::abs(u.x() * (p.y() - a.y()) - u.y() * (p.x() - a.x())) / n;
}

// Split-and-merge's split step: the run's rays [a, b] cut where the farthest point from the
// chord is farther than the tolerance.
void split(
    const std::vector<Ray>& run, int a, int b, double tol, std::vector<std::pair<int, int>>& out) {
  int worst = -1;
  double dmax = tol;
  for (int i = a + 1; i < b; ++i) {
    const double d = distance_to_chord(run[i].p, run[a].p, run[b].p);
    if (d > dmax) {
      dmax = d;
      worst = i;
    }
  }
  if (worst < 0) {
    out.emplace_back(a, b);
    return;
  }
  split(run, a, worst, tol, out);
  split(run, worst, b, tol, out);
}

// Split-and-merge's merge step: neighbouring pieces whose union is straight to the tolerance
// are one (the split can cut a straight wall where it is farthest from a long chord).
void merge(const std::vector<Ray>& run, double tol, std::vector<std::pair<int, int>>& cuts) {
  for (std::size_t i = 0; i + 1 < cuts.size();) {
    const int a = cuts[i].first, b = cuts[i + 1].second;
    double dmax = 0;
    for (int k = a + 1; k < b; ++k)
      dmax = std::max(dmax, distance_to_chord(run[k].p, run[a].p, run[b].p));
    if (dmax <= tol) {
      cuts[i].second = b;
      cuts.erase(cuts.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    } else {
      ++i;
    }
  }
}

// Total least squares line through rays [a, b], leaving out the ends shared with a
// neighbouring piece (they belong to the corner).
Piece fit(
    const std::vector<Ray>& run, int a, int b, bool trim_a, bool trim_b, const CornerOptions& o) {
  Piece p{a, b, Eigen::Vector2d::Zero(), Eigen::Vector2d::UnitX(), false};
  const int i0 = a + (trim_a ? 1 : 0), i1 = b - (trim_b ? 1 : 0);
  const int n = i1 - i0 + 1;
  if (n < o.min_points || (run[b].p - run[a].p).norm() < o.min_length) return p;
  Eigen::Vector2d m = Eigen::Vector2d::Zero();
  for (int i = i0; i <= i1; ++i) m += run[i].p;
  m /= n;
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
  for (int i = i0; i <= i1; ++i) S += (run[i].p - m) * (run[i].p - m).transpose();
  const double ang = 0.5 * std::atan2(2 * S(0, 1), S(0, 0) - S(1, 1));
  p.c = m;
  p.d = {std::cos(ang), std::sin(ang)};
  p.good = true;
  return p;
}

// Where the ray of direction angle `a` from the scanner meets the line of piece p.
bool ray_meets(const Piece& p, double a, Eigen::Vector2d& out) {
  const Eigen::Vector2d u(std::cos(a), std::sin(a));
  const double den = u.x() * p.d.y() - u.y() * p.d.x();
  if (std::abs(den) < 1e-9) return false;
  const double t = (p.c.x() * p.d.y() - p.c.y() * p.d.x()) / den;
  if (!(t > 0)) return false;
  out = t * u;
  return true;
}

bool lines_meet(const Piece& p, const Piece& q, Eigen::Vector2d& out) {
  const double den = p.d.x() * q.d.y() - p.d.y() * q.d.x();
  if (std::abs(den) < 1e-9) return false;
  const Eigen::Vector2d w = q.c - p.c;
  const double t = (w.x() * q.d.y() - w.y() * q.d.x()) / den;
  out = p.c + t * p.d;
  return true;
}

}  // namespace

std::vector<Eigen::Vector2d> scan_points(const dataset::LaserScan& s) {
  std::vector<Eigen::Vector2d> out;
  for (std::size_t k = 0; k < s.ranges.size(); ++k) {
    if (!s.valid(k)) continue;
    const double a = s.angle_min + static_cast<double>(k) * s.angle_increment;
    out.emplace_back(s.ranges[k] * std::cos(a), s.ranges[k] * std::sin(a));
  }
  return out;
}

std::vector<Eigen::Vector2d> scan_corners(const dataset::LaserScan& s,
                                          const CornerOptions& o,
                                          std::vector<Eigen::Vector2d>* ends) {
  if (ends) ends->clear();
  const int n = static_cast<int>(s.ranges.size());
  if (n < 2) return {};
  const double inc = s.angle_increment;
  const bool full = std::abs(inc) * n >= 2 * kPi - 1.5 * std::abs(inc);
  auto angle = [&](int k) { return s.angle_min + k * inc; };
  auto point = [&](int k) {
    return Eigen::Vector2d(s.ranges[k] * std::cos(angle(k)), s.ranges[k] * std::sin(angle(k)));
  };
  auto apart = [&](int i, int j) {  // consecutive valid rays on different surfaces
    return (point(i) - point(j)).norm() >
           o.jump + 0.03 * std::max<double>(s.ranges[i], s.ranges[j]);
  };
  // A full turn is walked from a boundary (a no return or a jump), so no run crosses the seam.
  int start = 0;
  if (full) {
    for (int k = 0; k < n; ++k) {
      const int prev = (k + n - 1) % n;
      if (!s.valid(k) || !s.valid(prev) || apart(k, prev)) {
        start = k;
        break;
      }
    }
  }
  // The neighbour beyond a run's end is farther (or gave no return): the run ends at an edge.
  auto farther = [&](int end, int beyond) {
    if (!full && (beyond < 0 || beyond >= n)) return false;
    beyond = (beyond + n) % n;
    const float r = s.ranges[beyond];
    if (std::isnan(r) || (std::isinf(r) && r < 0) || (std::isfinite(r) && r < s.range_min))
      return false;                                       // invalid or too close: unknown
    if (s.ranges[end] > 0.9 * s.range_max) return false;  // may go on beyond the range
    if (!s.valid(beyond)) return true;                    // nothing within range
    return s.ranges[beyond] > s.ranges[end] && apart(end, beyond);
  };
  std::vector<Eigen::Vector2d> corners;
  std::vector<Eigen::Vector2d>& end_points = ends ? *ends : corners;
  std::vector<Ray> run;
  auto close_run = [&]() {
    if (static_cast<int>(run.size()) < o.min_points) {
      run.clear();
      return;
    }
    std::vector<std::pair<int, int>> cuts;
    split(run, 0, static_cast<int>(run.size()) - 1, o.split_tolerance, cuts);
    merge(run, o.split_tolerance, cuts);
    std::vector<Piece> pieces;
    for (std::size_t i = 0; i < cuts.size(); ++i)
      pieces.push_back(fit(run, cuts[i].first, cuts[i].second, i > 0, i + 1 < cuts.size(), o));
    for (std::size_t i = 0; i + 1 < pieces.size(); ++i) {
      const Piece &p = pieces[i], &q = pieces[i + 1];
      if (!p.good || !q.good) continue;
      const double turn = std::acos(std::min(1.0, std::abs(p.d.dot(q.d))));
      Eigen::Vector2d c;
      if (turn < deg2rad(o.min_angle_deg) || !lines_meet(p, q, c)) continue;
      if ((c - run[p.b].p).norm() < 0.2) corners.push_back(c);
    }
    // The run's two ends: half a ray beyond the last point that hit, on the piece's line.
    const Piece& first = pieces.front();
    const Piece& last = pieces.back();
    const int k0 = run.front().k, k1 = run.back().k;
    Eigen::Vector2d c;
    if (first.good && farther(k0, k0 - 1) && ray_meets(first, angle(k0) - 0.5 * inc, c))
      end_points.push_back(c);
    if (last.good && farther(k1, k1 + 1) && ray_meets(last, angle(k1) + 0.5 * inc, c))
      end_points.push_back(c);
    run.clear();
  };
  for (int i = 0; i < n; ++i) {
    const int k = full ? (start + i) % n : i;
    if (!s.valid(k)) {
      close_run();
      continue;
    }
    if (!run.empty() && apart(run.back().k, k)) close_run();
    run.push_back({k, point(k), s.ranges[k]});
  }
  close_run();
  return corners;
}

double nearest_line_offset(double corner, const std::vector<double>& lines, double gate) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const double l : lines) {
    const double d = angle_diff(l, corner);
    if (std::abs(d) <= gate && !(std::abs(d) >= std::abs(best))) best = d;
  }
  return best;
}

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  double x = v[m];
  if (v.size() % 2 == 0) x = 0.5 * (x + *std::max_element(v.begin(), v.begin() + m));
  return x;
}

}  // namespace

std::vector<double> match_offsets(const std::vector<double>& refs,
                                  const std::vector<double>& lines,
                                  double gate) {
  std::vector<double> off(refs.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<int> line_of(refs.size(), -1);
  for (std::size_t i = 0; i < refs.size(); ++i)
    for (std::size_t j = 0; j < lines.size(); ++j) {
      const double d = angle_diff(lines[j], refs[i]);
      if (std::abs(d) <= gate && !(std::abs(d) >= std::abs(off[i]))) {
        off[i] = d;
        line_of[i] = static_cast<int>(j);
      }
    }
  // Mutual: the line's nearest reference must be this one (a line claimed once).
  for (std::size_t i = 0; i < refs.size(); ++i) {
    if (line_of[i] < 0) continue;
    const double l = lines[static_cast<std::size_t>(line_of[i])];
    for (std::size_t k = 0; k < refs.size(); ++k)
      if (k != i && std::abs(angle_diff(l, refs[k])) < std::abs(off[i])) {
        off[i] = std::numeric_limits<double>::quiet_NaN();
        break;
      }
  }
  return off;
}

OffsetStats corner_line_offsets(const References& refs,
                                const std::vector<std::vector<double>>& lines,
                                const calib::Extrinsics& mounting,
                                double gate,
                                bool ends) {
  OffsetStats st;
  std::vector<double> abs_d, signed_d;
  for (const FrameReference& f : refs.frames) {
    if (f.frame >= lines.size() || lines[f.frame].empty()) continue;
    ++st.frames;
    // Corners and ends compete for the lines together; the stats are of one kind.
    std::vector<double> b;
    for (const Eigen::Vector2d& c : f.corners) b.push_back(camera_bearing(mounting, c));
    for (const Eigen::Vector2d& c : f.ends) b.push_back(camera_bearing(mounting, c));
    const std::vector<double> off = match_offsets(b, lines[f.frame], gate);
    const std::size_t i0 = ends ? f.corners.size() : 0;
    const std::size_t i1 = ends ? b.size() : f.corners.size();
    for (std::size_t i = i0; i < i1; ++i) {
      ++st.corners;
      if (std::isnan(off[i])) continue;
      ++st.matched;
      abs_d.push_back(std::abs(off[i]));
      signed_d.push_back(off[i]);
    }
  }
  st.median_abs = median(abs_d);
  st.median_signed = median(signed_d);
  return st;
}

}  // namespace omnivert::pipeline
