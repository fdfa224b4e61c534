#include "omnivert/sim/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "omnivert/core/angles.hpp"
#include "sim/tilt_warp.hpp"

namespace omnivert::sim {

namespace {

constexpr int kBins = 4096;
constexpr double kPanelCell = 0.25;  // [m] cell size of the per-wall panel index          //
                                     // azimuth bins of the interval look-up
constexpr float kRimValue = 6.0f;    // outside the mirror: dark (the rim a circle detector finds)
constexpr float kSelfValue = 32.0f;  // the camera's own reflection inside r_min

// Fraction of [c - w/2, c + w/2] inside [lo, hi] (box filter of a step pair).
inline double coverage(double c, double w, double lo, double hi) {
  if (w <= 1e-12) return (c >= lo && c <= hi) ? 1.0 : 0.0;
  const double a = std::max(c - 0.5 * w, lo), b = std::min(c + 0.5 * w, hi);
  return b > a ? (b - a) / w : 0.0;
}

// Integral of the unit square wave (+1 on the first half period, -1 on the second).
inline double square_integral(double x) {
  const double f = x - std::floor(x);
  return 0.5 - std::abs(f - 0.5);
}

inline std::uint64_t mix(std::uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

inline double hash01(std::int64_t i, std::int64_t j, std::uint64_t seed) {
  const std::uint64_t h = mix(seed ^ mix(static_cast<std::uint64_t>(i) * 0x632be59bd9b4e019ULL ^
                                         mix(static_cast<std::uint64_t>(j))));
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

}  // namespace

struct Renderer::FrameState {
  double cx = 0, cy = 0, hc = 0, yaw = 0;
  int m = 0;                   // number of intervals (= number of distinct edge azimuths)
  std::vector<double> disc;    // sorted edge azimuths in [0, 2 pi), disc[m] = disc[0] + 2 pi
  std::vector<int> bin_start;  // interval containing the start of each azimuth bin
  std::vector<int> hit_offset;
  std::vector<int> hits;                    // walls met by the rays of each interval, nearest first
  std::vector<double> qx, qy, ux, uy, len;  // per wall: from - C, to - from, length

  // Azimuth of the global edge index j (periodic continuation).
  double disc_at(long j) const {
    const long q = (j >= 0 ? j / m : -((-j + m - 1) / m));
    return disc[static_cast<std::size_t>(j - q * m)] + kTwoPi * static_cast<double>(q);
  }
  // Global index j with disc_at(j) <= az < disc_at(j + 1).
  long find(double az) const {
    const double k = std::floor(az / kTwoPi);
    double a = az - kTwoPi * k;
    if (a >= kTwoPi) a = 0.0;
    const int b = std::min(static_cast<int>(a * (kBins / kTwoPi)), kBins - 1);
    int i = bin_start[static_cast<std::size_t>(b)];
    while (disc[static_cast<std::size_t>(i) + 1] <= a) ++i;
    return i + static_cast<long>(k) * m;
  }
  int interval_of(long j) const {
    const long r = j % m;
    return static_cast<int>(r < 0 ? r + m : r);
  }
};

Renderer::Renderer(const CatadioptricCamera& camera, const World& world)
    : camera_(camera), world_(world), edges_(world.edges()) {
  textures_.reserve(world_.walls.size());
  for (std::size_t i = 0; i < world_.walls.size(); ++i) {
    textures_.emplace_back(world_.walls[i], world_.height, world_.seed * 1000003ULL + i);
    wall_top_.push_back(world_.top(world_.walls[i]));
    // Panels overlapping each 0.25 m cell along the wall, in their drawing order (a later
    // panel covers an earlier one): a sample looks at a few panels, not all of them.
    const Wall& wall = world_.walls[i];
    const int cells = static_cast<int>(std::ceil(wall.length() / kPanelCell)) + 1;
    std::vector<std::vector<int>> index(static_cast<std::size_t>(cells));
    for (std::size_t k = 0; k < wall.panels.size(); ++k) {
      const Panel& p = wall.panels[k];
      const int c0 = std::clamp(static_cast<int>(std::floor(p.s0 / kPanelCell)), 0, cells - 1);
      const int c1 = std::clamp(static_cast<int>(std::floor(p.s1 / kPanelCell)), 0, cells - 1);
      for (int c = c0; c <= c1; ++c)
        index[static_cast<std::size_t>(c)].push_back(static_cast<int>(k));
    }
    panel_index_.push_back(std::move(index));
  }
  // Per-pixel table. Radius r of a pixel centre; its footprint is 1 px radially and
  // 1/r rad in azimuth.
  background_ = cv::Mat1f(camera_.height, camera_.width, kRimValue);
  const double r_in = world_r_in(), r_out = world_r_out();
  for (int v = 0; v < camera_.height; ++v) {
    for (int u = 0; u < camera_.width; ++u) {
      const double du = u - camera_.cx, dv = v - camera_.cy;
      const double r = std::hypot(du, dv);
      // Self-reflection disc and rim, anti-aliased by radial coverage.
      const double w_in = std::clamp(r - r_in + 0.5, 0.0, 1.0);
      const double w_out = std::clamp(r_out - r + 0.5, 0.0, 1.0);
      background_(v, u) = r < 0.5 * (r_in + r_out) ? kSelfValue : kRimValue;
      const double weight = w_in * w_out;
      if (weight <= 0.0) continue;
      const double a = std::atan2(dv, du);
      const double beta = camera_.bearing_sign * a;
      const double el = camera_.elevation_of_radius(r);
      const double el_lo = camera_.elevation_of_radius(std::max(r - 0.5, 0.0));
      const double el_hi = camera_.elevation_of_radius(r + 0.5);
      px_index_.push_back(v * camera_.width + u);
      px_beta_.push_back(static_cast<float>(beta));
      px_cos_.push_back(static_cast<float>(std::cos(beta)));
      px_sin_.push_back(static_cast<float>(std::sin(beta)));
      px_halfw_.push_back(static_cast<float>(0.5 / r));
      px_tan_.push_back(static_cast<float>(std::tan(el)));
      px_dtan_.push_back(static_cast<float>(std::tan(el_hi) - std::tan(el_lo)));
      px_weight_.push_back(static_cast<float>(weight));
    }
  }
  if (camera_.tilt_deg != 0.0) {
    tilt_ = std::make_shared<const TiltWarp>(camera_, world_, px_index_, px_weight_);
  }
}

cv::Mat1f Renderer::render(const CameraPose& pose) const {
  cv::Mat1f img;
  render(pose, img);
  return img;
}

void Renderer::setup_walls(const CameraPose& pose, FrameState& f) const {
  f.cx = pose.x;
  f.cy = pose.y;
  f.hc = pose.height;
  f.yaw = pose.yaw;
  const std::size_t nw = world_.walls.size();
  f.qx.resize(nw);
  f.qy.resize(nw);
  f.ux.resize(nw);
  f.uy.resize(nw);
  f.len.resize(nw);
  for (std::size_t i = 0; i < nw; ++i) {
    const Wall& w = world_.walls[i];
    f.qx[i] = w.from.x() - pose.x;
    f.qy[i] = w.from.y() - pose.y;
    f.ux[i] = w.to.x() - w.from.x();
    f.uy[i] = w.to.y() - w.from.y();
    f.len[i] = w.length();
  }
}

void Renderer::render(const CameraPose& pose, cv::Mat1f& image) const {
  if (tilt_) {
    tilt_->render(pose, background_, image);
    return;
  }
  FrameState f;
  setup_walls(pose, f);
  const std::size_t nw = world_.walls.size();
  // Edge azimuths: the only places where the walls met by a ray, or a wall's texture,
  // change discontinuously.
  f.disc.reserve(edges_.size() + 2);
  f.disc.push_back(0.0);
  for (const VerticalEdge& e : edges_) {
    f.disc.push_back(wrap_positive(std::atan2(e.p.y() - pose.y, e.p.x() - pose.x)));
  }
  std::sort(f.disc.begin(), f.disc.end());
  f.disc.erase(std::unique(f.disc.begin(), f.disc.end()), f.disc.end());
  f.m = static_cast<int>(f.disc.size());
  f.disc.push_back(f.disc.front() + kTwoPi);
  f.bin_start.resize(kBins);
  {
    int i = 0;
    for (int b = 0; b < kBins; ++b) {
      const double a = b * (kTwoPi / kBins);
      while (f.disc[static_cast<std::size_t>(i) + 1] <= a) ++i;
      f.bin_start[static_cast<std::size_t>(b)] = i;
    }
  }
  // One ray per interval: the walls it meets, nearest first.
  f.hit_offset.reserve(static_cast<std::size_t>(f.m) + 1);
  std::vector<std::pair<double, int>> tmp;
  for (int i = 0; i < f.m; ++i) {
    f.hit_offset.push_back(static_cast<int>(f.hits.size()));
    const double az =
        0.5 * (f.disc[static_cast<std::size_t>(i)] + f.disc[static_cast<std::size_t>(i) + 1]);
    const double dx = std::cos(az), dy = std::sin(az);
    tmp.clear();
    for (std::size_t w = 0; w < nw; ++w) {
      const double den = cross(dx, dy, f.ux[w], f.uy[w]);
      if (std::abs(den) < 1e-14) continue;
      const double t = cross(f.qx[w], f.qy[w], f.ux[w], f.uy[w]) / den;
      const double sigma = cross(f.qx[w], f.qy[w], dx, dy) / den;
      if (t > 1e-9 && sigma >= 0.0 && sigma <= 1.0) tmp.emplace_back(t, static_cast<int>(w));
    }
    std::sort(tmp.begin(), tmp.end());
    for (const auto& h : tmp) f.hits.push_back(h.second);
  }
  f.hit_offset.push_back(static_cast<int>(f.hits.size()));

  background_.copyTo(image);
  float* out = image.ptr<float>();
  const double cyaw = std::cos(pose.yaw), syaw = std::sin(pose.yaw);
  for (std::size_t k = 0; k < px_index_.size(); ++k) {
    const double halfw = px_halfw_[k];
    const double az = pose.yaw + px_beta_[k];
    const double a0 = az - halfw, a1 = az + halfw;
    const long j0 = f.find(a0);
    const double next = f.disc_at(j0 + 1);
    double value;
    if (next >= a1) {
      // No vertical edge inside the footprint: one sample at the pixel centre.
      const double c = px_cos_[k], sn = px_sin_[k];
      value = shade(f,
                    f.interval_of(j0),
                    cyaw * c - syaw * sn,
                    syaw * c + cyaw * sn,
                    px_tan_[k],
                    px_dtan_[k],
                    halfw);
    } else {
      // Split the footprint at the edges it contains; one sample per piece, weighted by
      // its azimuthal length (exact coverage for the vertical discontinuities).
      value = 0.0;
      double lo = a0;
      long j = j0;
      while (lo < a1) {
        const double hi = std::min(f.disc_at(j + 1), a1);
        if (hi > lo) {
          const double mid = 0.5 * (lo + hi);
          value += (hi - lo) * shade(f,
                                     f.interval_of(j),
                                     std::cos(mid),
                                     std::sin(mid),
                                     px_tan_[k],
                                     px_dtan_[k],
                                     halfw);
        }
        lo = hi;
        ++j;
      }
      value /= (a1 - a0);
    }
    const int idx = px_index_[k];
    const float w = px_weight_[k];
    out[idx] = w * static_cast<float>(value) + (1.0f - w) * out[idx];
  }
}

float Renderer::shade(const FrameState& f,
                      int interval,
                      double dx,
                      double dy,
                      double tan_el,
                      double dtan,
                      double halfw) const {
  const int* hits = f.hits.data();
  return shade_hits(f,
                    hits + f.hit_offset[static_cast<std::size_t>(interval)],
                    hits + f.hit_offset[static_cast<std::size_t>(interval) + 1],
                    dx,
                    dy,
                    tan_el,
                    dtan,
                    halfw);
}

float Renderer::shade_hits(const FrameState& f,
                           const int* h0,
                           const int* h1,
                           double dx,
                           double dy,
                           double tan_el,
                           double dtan,
                           double halfw) const {
  double acc = 0.0, remaining = 1.0;
  for (const int* h = h0; h < h1 && remaining > 1e-4; ++h) {
    const int w = *h;
    const double den = cross(dx, dy, f.ux[w], f.uy[w]);
    if (std::abs(den) < 1e-14) continue;
    const double t = cross(f.qx[w], f.qy[w], f.ux[w], f.uy[w]) / den;
    if (t <= 0.0) continue;
    const double sigma = std::clamp(cross(f.qx[w], f.qy[w], dx, dy) / den, 0.0, 1.0);
    const double z = f.hc + t * tan_el, dz = t * dtan;
    const Wall& wall = world_.walls[static_cast<std::size_t>(w)];
    const double cov = coverage(z,
                                dz,
                                std::max(wall.z0, 0.0),
                                std::min(wall_top_[static_cast<std::size_t>(w)], world_.height));
    if (cov <= 0.0) continue;
    // Footprint along the wall: the tangential footprint t * 2 halfw, stretched by the
    // incidence (|den| / len is the sine of the angle between ray and wall).
    const double ds = std::min(t * 2.0 * halfw * f.len[w] / std::abs(den), 1.0);
    acc += remaining * cov * wall_texture(w, sigma * f.len[w], z, ds, dz);
    remaining *= 1.0 - cov;
  }
  if (remaining > 1e-4) {
    if (tan_el < -1e-9) {
      const double t = f.hc / -tan_el;
      const double fp = std::max(t * 2.0 * halfw, f.hc / (tan_el * tan_el) * dtan);
      acc += remaining * plane_texture(world_.floor, f.cx + t * dx, f.cy + t * dy, fp, false);
    } else if (tan_el > 1e-9) {
      const double t = (world_.height - f.hc) / tan_el;
      const double fp =
          std::max(t * 2.0 * halfw, (world_.height - f.hc) / (tan_el * tan_el) * dtan);
      acc += remaining * plane_texture(world_.ceiling, f.cx + t * dx, f.cy + t * dy, fp, true);
    } else {
      acc += remaining * 0.5 * (world_.floor.intensity + world_.ceiling.intensity);
    }
  }
  return static_cast<float>(acc);
}

float Renderer::wall_texture(int wi, double s, double z, double ds, double dz) const {
  const Wall& w = world_.walls[static_cast<std::size_t>(wi)];
  double v = w.intensity;
  for (const Strip& st : w.strips) {
    if (s >= st.s0 && s < st.s1) v = st.intensity;
  }
  v += textures_[static_cast<std::size_t>(wi)].noise(s, z);
  const auto& cells = panel_index_[static_cast<std::size_t>(wi)];
  const int cell = std::clamp(
      static_cast<int>(std::floor(s / kPanelCell)), 0, static_cast<int>(cells.size()) - 1);
  for (const int k : cells[static_cast<std::size_t>(cell)]) {
    const Panel& p = w.panels[static_cast<std::size_t>(k)];
    if (s < p.s0 || s >= p.s1) continue;
    const double cov = coverage(z, dz, p.z0, p.z1);
    if (cov <= 0.0) continue;
    double pv = p.intensity;
    switch (p.pattern) {
      case Pattern::kStripes: {
        const double x = (z - p.z0) / p.period, dx = dz / p.period;
        const double sq =
            dx > 1e-6 ? 2.0 * (square_integral(x + 0.5 * dx) - square_integral(x - 0.5 * dx)) / dx
                      : (x - std::floor(x) < 0.5 ? 1.0 : -1.0);
        pv += p.amplitude * sq;
        break;
      }
      case Pattern::kWave: {
        // Box-filtered over the footprint: the sine's amplitude times sinc(width / period).
        const double q = deg2rad(p.angle_deg), cq = std::cos(q), sq = std::sin(q);
        const double x = kPi * std::hypot(ds * cq, dz * sq) / p.period;
        const double att = x < 1e-6 ? 1.0 : std::sin(x) / x;
        pv += att * p.amplitude * std::sin(kTwoPi * ((s - p.s0) * cq + (z - p.z0) * sq) / p.period);
        break;
      }
      case Pattern::kFlat:
        break;
    }
    // The panel keeps a fainter copy of the wall's noise, so that it is not flat.
    pv += 0.5 * textures_[static_cast<std::size_t>(wi)].noise(s + 0.37, z + 0.21);
    v += cov * (pv - v);
  }
  return static_cast<float>(v);
}

float Renderer::plane_texture(
    const Plane& p, double x, double y, double footprint, bool ceiling) const {
  // Tiles with their own grey level; the footprint blends neighbouring tiles near a joint.
  const double gx = x / p.tile, gy = y / p.tile;
  const double fx = gx - std::floor(gx), fy = gy - std::floor(gy);
  const double fp = std::min(footprint / p.tile, 1.0);
  const auto ix = static_cast<std::int64_t>(std::floor(gx));
  const auto iy = static_cast<std::int64_t>(std::floor(gy));
  auto tile = [&](std::int64_t i, std::int64_t j) {
    const double h = hash01(i, j, world_.seed + (ceiling ? 77 : 0));
    if (ceiling && h > 0.88) return 252.0;  // a lamp
    const double parity = ((i + j) & 1) ? 0.35 : -0.35;
    return p.intensity + p.contrast * (parity + 1.3 * (h - 0.5));
  };
  // Weight of the neighbour across the nearer joint, per axis.
  auto neighbour = [&](double frac, int& side) {
    if (frac < 0.5) {
      side = -1;
      return std::clamp((0.5 * fp - frac) / std::max(fp, 1e-9), 0.0, 0.5);
    }
    side = 1;
    return std::clamp((0.5 * fp - (1.0 - frac)) / std::max(fp, 1e-9), 0.0, 0.5);
  };
  int sx = 0, sy = 0;
  const double wx = neighbour(fx, sx), wy = neighbour(fy, sy);
  double v = (1 - wx) * (1 - wy) * tile(ix, iy);
  if (wx > 0) v += wx * (1 - wy) * tile(ix + sx, iy);
  if (wy > 0) v += (1 - wx) * wy * tile(ix, iy + sy);
  if (wx > 0 && wy > 0) v += wx * wy * tile(ix + sx, iy + sy);
  return static_cast<float>(v);
}

void Renderer::render_reference(const CameraPose& pose, int samples, cv::Mat1f& image) const {
  FrameState f;
  setup_walls(pose, f);
  background_.copyTo(image);
  float* out = image.ptr<float>();
  std::vector<std::pair<double, int>> tmp;
  std::vector<int> hits;
  for (std::size_t k = 0; k < px_index_.size(); ++k) {
    const double halfw = px_halfw_[k];
    const double az0 = pose.yaw + px_beta_[k] - halfw;
    double value = 0.0;
    for (int q = 0; q < samples; ++q) {
      const double az = az0 + (q + 0.5) * (2.0 * halfw / samples);
      const double dx = std::cos(az), dy = std::sin(az);
      // Every wall, nearest first.
      tmp.clear();
      for (std::size_t w = 0; w < world_.walls.size(); ++w) {
        const double den = cross(dx, dy, f.ux[w], f.uy[w]);
        if (std::abs(den) < 1e-14) continue;
        const double t = cross(f.qx[w], f.qy[w], f.ux[w], f.uy[w]) / den;
        const double sigma = cross(f.qx[w], f.qy[w], dx, dy) / den;
        if (t > 1e-9 && sigma >= 0.0 && sigma <= 1.0) tmp.emplace_back(t, static_cast<int>(w));
      }
      std::sort(tmp.begin(), tmp.end());
      hits.clear();
      for (const auto& h : tmp) hits.push_back(h.second);
      // Texture filters use the sub-sample's own footprint.
      value += shade_hits(f,
                          hits.data(),
                          hits.data() + hits.size(),
                          dx,
                          dy,
                          px_tan_[k],
                          px_dtan_[k],
                          halfw / samples);
    }
    const int idx = px_index_[k];
    const float w = px_weight_[k];
    out[idx] = w * static_cast<float>(value / samples) + (1.0f - w) * out[idx];
  }
}

std::vector<VisibleLine> Renderer::visible_lines(const CameraPose& pose,
                                                 double min_length_px) const {
  std::vector<VisibleLine> out;
  const double el_min = camera_.elevation_of_radius(camera_.r_min);
  const double el_max = camera_.elevation_of_radius(camera_.r_max);
  for (const VerticalEdge& e : edges_) {
    const double ex = e.p.x() - pose.x, ey = e.p.y() - pose.y;
    const double d = std::hypot(ex, ey);
    if (d < 1e-6) continue;
    double lo = std::max(std::atan2(e.z0 - pose.height, d), el_min);
    double hi = std::min(std::atan2(e.z1 - pose.height, d), el_max);
    if (hi <= lo) continue;
    // Visible elevation intervals: [lo, hi] minus what nearer walls hide.
    std::vector<std::pair<double, double>> vis{{lo, hi}};
    const double dx = ex / d, dy = ey / d;
    for (std::size_t wi = 0; wi < world_.walls.size() && !vis.empty(); ++wi) {
      const Wall& w = world_.walls[wi];
      const Eigen::Vector2d u = w.to - w.from;
      // Walls through the edge itself do not hide it.
      const double len2 = u.squaredNorm();
      const double proj = std::clamp((e.p - w.from).dot(u) / len2, 0.0, 1.0);
      if ((w.from + proj * u - e.p).norm() < 1e-3) continue;
      const double qx = w.from.x() - pose.x, qy = w.from.y() - pose.y;
      const double den = cross(dx, dy, u.x(), u.y());
      if (std::abs(den) < 1e-14) continue;
      const double t = cross(qx, qy, u.x(), u.y()) / den;
      const double sigma = cross(qx, qy, dx, dy) / den;
      if (!(t > 1e-9 && t < d - 1e-6 && sigma >= 0.0 && sigma <= 1.0)) continue;
      const double olo = std::atan2(std::max(w.z0, 0.0) - pose.height, t);
      const double ohi = std::atan2(std::min(world_.top(w), world_.height) - pose.height, t);
      std::vector<std::pair<double, double>> next;
      for (const auto& [a, b] : vis) {
        if (ohi <= a || olo >= b) {
          next.emplace_back(a, b);
          continue;
        }
        if (olo > a) next.emplace_back(a, olo);
        if (ohi < b) next.emplace_back(ohi, b);
      }
      vis.swap(next);
    }
    if (vis.empty()) continue;
    // The longest visible piece.
    auto best = *std::max_element(vis.begin(), vis.end(), [](const auto& p, const auto& q) {
      return p.second - p.first < q.second - q.first;
    });
    VisibleLine l;
    l.line_id = e.id;
    l.bearing = wrap_angle(std::atan2(ey, ex) - pose.yaw);
    l.r_inner = camera_.radius_of_elevation(best.first);
    l.r_outer = camera_.radius_of_elevation(best.second);
    l.distance = d;
    if (l.r_outer - l.r_inner >= min_length_px) out.push_back(l);
  }
  return out;
}

}  // namespace omnivert::sim
