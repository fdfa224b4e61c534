// Triangulated prediction and links by prediction of the tracker (TrackerOptions::triangulate,
// predict_f1; docs/theory/matching.md#triangulated-prediction): where a track's line is, from
// its bearings and the wheels, and the links that position makes certain.
#include <algorithm>
#include <cmath>
#include <tuple>

#include "omnivert/core/angles.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert {
namespace {

// Straight travel: the heading changed by at most this since the anchor (radians). The camera
// sits up to rho_max off the axle; a turn moves it by rho |d_theta| more than the axle.
constexpr double kStraight = 0.03;
// Rays closer to parallel than this (radians) locate a line too poorly: the relative error of
// its distance is about sqrt(2) sigma_beta / angle (8 % at 0.03 degree of bearing noise).
constexpr double kMinParallax = 0.0087;
// Fraction of the predicted bearing change allowed as error (the position's error).
constexpr double kChangeError = 0.1;
// Votes on the camera's yaw from links between frames at most this many apart.
constexpr int kVoteBack = 3;

}  // namespace

bool Tracker::predict_from_position(const Slot& s, int j, TrackPrediction* p) const {
  if (!options_.triangulate || std::isnan(camera_yaw_)) return false;
  const LineGeometry& g = s.geometry[static_cast<std::size_t>(j)];
  if (std::isnan(g.px) || std::abs(odometry_.theta - g.p_theta) > kStraight) return false;
  const double dx = g.px - odometry_.x, dy = g.py - odometry_.y;
  const double distance = std::hypot(dx, dy);
  // Eq. (16) with the camera at the axle: u = beta + theta = atan2(...) - (phi + psi).
  p->u = std::atan2(dy, dx) - g.p_yaw;
  const double u_before = s.bearings[static_cast<std::size_t>(j)] + s.odometry.theta;
  const double d_theta = odometry_.theta - g.p_theta;
  const double swing = 2.0 * options_.gate.max_camera_offset * std::abs(std::sin(0.5 * d_theta));
  p->spread = kChangeError * std::abs(angle_diff(p->u, u_before)) +
              (swing < distance ? std::asin(swing / distance) : kPi);
  p->rates_known = true;
  p->triangulated = true;
  return true;
}

void Tracker::measure_track_geometry(const FrameFeatures& frame,
                                     const std::vector<TrackAssignment>& out) {
  const int n = static_cast<int>(frame.lines.size());
  geometry_.assign(static_cast<std::size_t>(n), LineGeometry{});
  if (!options_.triangulate || !options_.gate.enabled) return;
  for (int i = 0; i < n; ++i) {
    const double beta = frame.lines[static_cast<std::size_t>(i)].bearing;
    const double u = beta + odometry_.theta;
    const TrackAssignment& a = out[static_cast<std::size_t>(i)];
    LineGeometry g;
    if (a.frames_back >= 1 && a.matched_line >= 0) {
      const Slot& s0 = slot_back(a.frames_back);
      const auto j = static_cast<std::size_t>(a.matched_line);
      g = s0.geometry[j];
      const double d_theta = odometry_.theta - s0.odometry.theta;
      const double path = odometry_.path_length - s0.odometry.path_length;
      // The sign of the parallax on a straight link votes on the camera's yaw.
      if (a.frames_back <= kVoteBack && path > 0.01 && std::abs(d_theta) <= 0.02) {
        const double beta0 = s0.bearings[j];
        yaw_votes_.add(beta0 + 0.5 * angle_diff(beta, beta0),
                       angle_diff(u, beta0 + s0.odometry.theta));
      }
    }
    const bool straight =
        !std::isnan(g.a_theta) && std::abs(odometry_.theta - g.a_theta) <= kStraight;
    if (straight && !std::isnan(camera_yaw_) &&
        std::hypot(odometry_.x - g.ax, odometry_.y - g.ay) > 0.01) {
      double px = 0.0, py = 0.0;
      if (intersect_rays(g.ax,
                         g.ay,
                         g.au + camera_yaw_,
                         odometry_.x,
                         odometry_.y,
                         u + camera_yaw_,
                         kMinParallax,
                         &px,
                         &py)) {
        g.px = px;
        g.py = py;
        g.p_theta = odometry_.theta;
        g.p_yaw = camera_yaw_;
      }
    }
    if (!straight) {
      g.ax = odometry_.x;
      g.ay = odometry_.y;
      g.au = u;
      g.a_theta = odometry_.theta;
    }
    g.fresh = a.frames_back == 0;
    geometry_[static_cast<std::size_t>(i)] = g;
  }
}

void Tracker::link_by_prediction(const FrameFeatures& frame, std::vector<TrackAssignment>* out) {
  if (!(options_.predict_f1 > 0.0) || unmatched_.empty()) return;
  // The latest observation of each track not yet continued in this frame, over the look-back.
  const int held = static_cast<int>(std::min<std::int64_t>(frame_count_, options_.look_back));
  heads_.clear();
  latest_.clear();
  for (int k = 1; k <= held; ++k) {
    const Slot& s = slot_back(k);
    for (int j = 0; j < s.num_lines; ++j)
      latest_.push_back({s.track_ids[static_cast<std::size_t>(j)], k, j});
  }
  std::sort(latest_.begin(), latest_.end());  // by track, then most recent first
  for (std::size_t n = 0; n < latest_.size(); ++n) {
    const auto [id, k, j] = latest_[n];
    if ((n > 0 && std::get<0>(latest_[n - 1]) == id) || track_claimed(id)) continue;
    TrackPrediction p;
    if (!predict_from_position(slot_back(k), j, &p)) continue;
    heads_.push_back({k,
                      j,
                      p.u,
                      options_.confirm_tolerance + p.spread,
                      options_.continuity_tolerance + p.spread});
  }
  if (held >= 2) add_pair_heads();
  auto u_of = [&](int a) {
    return frame.lines[static_cast<std::size_t>(a)].bearing + odometry_.theta;
  };
  auto polarity_differs = [](int p, int q) { return p != 0 && q != 0 && p != q; };
  still_unmatched_.clear();
  for (int a : unmatched_) {
    const int pa = frame.lines[static_cast<std::size_t>(a)].polarity;
    const Head* match = nullptr;
    int near_heads = 0;
    for (const Head& h : heads_) {
      const Slot& s = slot_back(h.k);
      if (polarity_differs(pa, s.polarities[static_cast<std::size_t>(h.j)])) continue;
      const double d = std::abs(angle_diff(u_of(a), h.u));
      if (d <= h.wide) ++near_heads;
      if (d <= h.tight) match = &h;
    }
    bool ok = match != nullptr && near_heads == 1 &&
              !track_claimed(slot_back(match->k).track_ids[static_cast<std::size_t>(match->j)]);
    if (ok) {  // no other line of that polarity could continue the track
      const Slot& s = slot_back(match->k);
      const int ps = s.polarities[static_cast<std::size_t>(match->j)];
      for (std::size_t b = 0; b < frame.lines.size() && ok; ++b) {
        if (static_cast<int>(b) == a || polarity_differs(frame.lines[b].polarity, ps)) continue;
        if (std::abs(angle_diff(u_of(static_cast<int>(b)), match->u)) <= match->wide) ok = false;
      }
    }
    float distance = 0.0f;
    if (ok) {
      const Slot& s = slot_back(match->k);
      distance = std::sqrt(descriptor_distance_sq(
          options_.match, frame.descriptors.row(a), s.descriptors.row(match->j)));
      ok = distance <= options_.predict_f1;
    }
    if (!ok) {
      still_unmatched_.push_back(a);
      continue;
    }
    const Slot& s = slot_back(match->k);
    TrackAssignment& t = (*out)[static_cast<std::size_t>(a)];
    t.track_id = s.track_ids[static_cast<std::size_t>(match->j)];
    t.frames_back = match->k;
    t.matched_line = match->j;
    t.distance = distance;
    claimed_.push_back(t.track_id);
    ++stats_.linked_by_prediction;
    ++(match->k == 1 ? stats_.matched_previous : stats_.matched_look_back);
  }
  unmatched_.swap(still_unmatched_);
}

void Tracker::add_pair_heads() {
  // A near line passed fast changes its descriptor beyond every test from frame to frame and
  // starts a new track in each; three rays that meet in one point link it again.
  const Slot& s1 = slot_back(1);
  const Slot& s2 = slot_back(2);
  if (std::isnan(camera_yaw_) || std::abs(odometry_.theta - s2.odometry.theta) > kStraight ||
      std::hypot(s1.odometry.x - s2.odometry.x, s1.odometry.y - s2.odometry.y) <= 0.01) {
    return;
  }
  const BearingGate gate = make_bearing_gate(options_.gate, s2.odometry, s1.odometry);
  for (int j1 = 0; j1 < s1.num_lines; ++j1) {
    const auto i1 = static_cast<std::size_t>(j1);
    if (!s1.geometry[i1].fresh || track_claimed(s1.track_ids[i1])) continue;
    const double u1 = s1.bearings[i1] + s1.odometry.theta;
    for (std::size_t n = 0; n < latest_.size(); ++n) {
      const auto [id, k, j2] = latest_[n];
      if (k != 2 || (n > 0 && std::get<0>(latest_[n - 1]) == id) || track_claimed(id)) continue;
      const auto i2 = static_cast<std::size_t>(j2);
      const int p1 = s1.polarities[i1], p2 = s2.polarities[i2];
      if ((p1 != 0 && p2 != 0 && p1 != p2) || !gate.admits(s2.bearings[i2], s1.bearings[i1]))
        continue;
      double px = 0.0, py = 0.0;
      if (!intersect_rays(s2.odometry.x,
                          s2.odometry.y,
                          s2.bearings[i2] + s2.odometry.theta + camera_yaw_,
                          s1.odometry.x,
                          s1.odometry.y,
                          u1 + camera_yaw_,
                          kMinParallax,
                          &px,
                          &py)) {
        continue;
      }
      const double u = std::atan2(py - odometry_.y, px - odometry_.x) - camera_yaw_;
      const double spread = kChangeError * std::abs(angle_diff(u, u1));
      heads_.push_back(
          {1, j1, u, options_.confirm_tolerance + spread, options_.continuity_tolerance + spread});
    }
  }
}

}  // namespace omnivert
