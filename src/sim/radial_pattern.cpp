#include "omnivert/sim/radial_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "omnivert/core/angles.hpp"

namespace omnivert::sim {

namespace {

struct Patch {
  double a0, a1;  // angular interval (a0 < a1, both in [0, 2 pi))
  double r0, r1;
  double level;
};

struct Blob {
  double x, y, sigma, amplitude;
};

}  // namespace

RadialPattern draw_radial_pattern(const RadialPatternOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  RadialPattern out;
  const double cx = (o.width - 1) / 2.0 + (2 * U(rng) - 1) * o.center_jitter;
  const double cy = (o.height - 1) / 2.0 + (2 * U(rng) - 1) * o.center_jitter;
  out.circle.center = {cx, cy};
  out.circle.r_min = o.r_min;
  out.circle.r_max = o.r_max;
  out.circle.rim_radius = o.rim_radius;
  const double sep = deg2rad(o.min_separation_deg);

  // Sector boundaries with a minimum separation (rejection sampling).
  std::vector<double> bounds;
  for (int tries = 0; static_cast<int>(bounds.size()) < o.full_edges && tries < 10000; ++tries) {
    const double a = U(rng) * kTwoPi;
    bool ok = true;
    for (double b : bounds) ok = ok && std::abs(angle_diff(a, b)) >= 3 * sep;
    if (ok) bounds.push_back(a);
  }
  std::sort(bounds.begin(), bounds.end());
  const int ns = static_cast<int>(bounds.size());
  // Sector k spans [bounds[k], bounds[k+1]); grey levels with the required contrast.
  std::vector<double> level(ns);
  double g = 60 + 120 * U(rng);
  for (int k = 0; k < ns; ++k) {
    level[k] = g;
    double c = o.min_contrast + (o.max_contrast - o.min_contrast) * U(rng);
    double up = g + c, down = g - c;
    g = (up <= 235 && (down < 20 || U(rng) < 0.5)) ? up : (down >= 20 ? down : up);
  }
  // Wrap-around: the last sector meets the first; fix its level if contrast is too small.
  if (ns > 1 && std::abs(level[ns - 1] - level[0]) < o.min_contrast) {
    level[ns - 1] = level[0] + (level[0] < 128 ? 1 : -1) * (o.min_contrast + 10);
    if (ns > 2 && std::abs(level[ns - 1] - level[ns - 2]) < o.min_contrast)
      level[ns - 1] = level[0] + (level[0] < 128 ? 1 : -1) * (o.max_contrast);
  }
  for (int k = 0; k < ns; ++k) {
    out.edges.push_back({wrap_angle(bounds[k]), o.r_min, o.r_max, true});
  }
  auto sector_of = [&](double a) {
    // a in [0, 2 pi)
    auto it = std::upper_bound(bounds.begin(), bounds.end(), a);
    int k = static_cast<int>(it - bounds.begin()) - 1;
    return k < 0 ? ns - 1 : k;
  };

  // Patches inside one sector, away from its boundaries and from each other.
  std::vector<Patch> patches;
  for (int tries = 0; static_cast<int>(patches.size()) < o.patches && tries < 10000; ++tries) {
    const double a0 = U(rng) * kTwoPi;
    const double width = deg2rad(6 + 20 * U(rng));
    const double a1 = a0 + width;
    bool ok = a1 < kTwoPi;
    for (const auto& e : out.edges) {
      ok = ok && std::abs(angle_diff(a0, e.image_angle)) >= sep &&
           std::abs(angle_diff(a1, e.image_angle)) >= sep;
    }
    if (ok) {
      // Not across a sector boundary.
      const int k0 = sector_of(a0), k1 = sector_of(std::fmod(a1, kTwoPi));
      ok = k0 == k1;
      for (double b : bounds) ok = ok && !(b > a0 && b < a1);
    }
    for (const auto& p : patches) ok = ok && (a1 + sep < p.a0 || a0 > p.a1 + sep);
    if (!ok) continue;
    const double L = o.r_max - o.r_min;
    const double frac = 0.25 + 0.7 * U(rng);
    const double r0 = o.r_min + (1 - frac) * L * U(rng);
    const double r1 = r0 + frac * L;
    const double base = level[sector_of(a0)];
    const double c = o.min_contrast + (o.max_contrast - o.min_contrast) * U(rng);
    const double lv = (base + c <= 235 && (base - c < 20 || U(rng) < 0.5)) ? base + c : base - c;
    patches.push_back({a0, a1, r0, r1, lv});
    out.edges.push_back({wrap_angle(a0), r0, r1, false});
    out.edges.push_back({wrap_angle(a1), r0, r1, false});
  }

  std::vector<Blob> blobs;
  if (o.texture) {
    for (int i = 0; i < 60; ++i) {
      const double r = o.r_min + (o.r_max - o.r_min) * U(rng);
      const double a = U(rng) * kTwoPi;
      blobs.push_back(
          {cx + r * std::cos(a), cy + r * std::sin(a), 4 + 10 * U(rng), (2 * U(rng) - 1) * 12});
    }
  }

  // Rotation of the scene: evaluate the unrotated scene at angle - rotation.
  const double rot = o.rotation_rad;
  const double cr = std::cos(rot), sr = std::sin(rot);
  for (Blob& b : blobs) {
    const double bx = b.x - cx, by = b.y - cy;
    b.x = cx + cr * bx - sr * by;
    b.y = cy + sr * bx + cr * by;
  }
  for (auto& e : out.edges) e.image_angle = wrap_angle(e.image_angle + rot);
  const double r_disc = o.r_min / 1.1;
  auto value = [&](double x, double y) {
    const double dx = x - cx, dy = y - cy;
    const double r = std::sqrt(dx * dx + dy * dy);
    if (r > o.rim_radius) return 12.0;
    if (r < r_disc) return 25.0;
    const double a = wrap_positive(std::atan2(dy, dx) - rot);
    for (const Patch& p : patches)
      if (a >= p.a0 && a < p.a1 && r >= p.r0 && r < p.r1) return p.level;
    return level[sector_of(a)];
  };
  // Which region a point is in, to find the pixels that a boundary crosses.
  auto region = [&](double x, double y) {
    const double dx = x - cx, dy = y - cy;
    const double r = std::sqrt(dx * dx + dy * dy);
    if (r > o.rim_radius) return -1;
    if (r < r_disc) return -2;
    const double a = wrap_positive(std::atan2(dy, dx) - rot);
    for (std::size_t i = 0; i < patches.size(); ++i) {
      const Patch& p = patches[i];
      if (a >= p.a0 && a < p.a1 && r >= p.r0 && r < p.r1) return 1000 + static_cast<int>(i);
    }
    return sector_of(a);
  };

  cv::Mat img(o.height, o.width, CV_32F);
  const int ss = 8;  // 8 x 8 supersampling where a boundary crosses the pixel
  for (int v = 0; v < o.height; ++v) {
    float* row = img.ptr<float>(v);
    for (int u = 0; u < o.width; ++u) {
      // A pixel is uniform if its centre and a ring of points at its border agree.
      const int r0 = region(u, v);
      bool uniform = true;
      for (int k = 0; k < 8 && uniform; ++k) {
        const double a = k * kPi / 4;
        uniform = region(u + 0.75 * std::cos(a), v + 0.75 * std::sin(a)) == r0;
      }
      double val;
      if (uniform) {
        val = value(u, v);
      } else {
        double acc = 0;
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i)
            acc += value(u - 0.5 + (i + 0.5) / ss, v - 0.5 + (j + 0.5) / ss);
        val = acc / (ss * ss);
      }
      row[u] = static_cast<float>(val);
    }
  }
  // Smooth texture (added to every pixel inside the mirror), then noise.
  if (!blobs.empty()) {
    for (int v = 0; v < o.height; ++v) {
      float* row = img.ptr<float>(v);
      for (int u = 0; u < o.width; ++u) {
        const double dx = u - cx, dy = v - cy;
        const double r = std::sqrt(dx * dx + dy * dy);
        if (r > o.rim_radius - 1 || r < r_disc + 1) continue;
        double t = 0;
        for (const Blob& b : blobs) {
          const double ex = u - b.x, ey = v - b.y;
          const double d2 = ex * ex + ey * ey;
          if (d2 < 9 * b.sigma * b.sigma)
            t += b.amplitude * std::exp(-d2 / (2 * b.sigma * b.sigma));
        }
        row[u] += static_cast<float>(t);
      }
    }
  }
  if (o.noise_seed != 0) rng.seed(o.noise_seed);
  std::normal_distribution<double> N(0.0, o.noise_sigma);
  out.image.create(o.height, o.width, CV_8U);
  for (int v = 0; v < o.height; ++v) {
    const float* src = img.ptr<float>(v);
    uchar* dst = out.image.ptr<uchar>(v);
    for (int u = 0; u < o.width; ++u) {
      const double val = src[u] + (o.noise_sigma > 0 ? N(rng) : 0.0);
      dst[u] = static_cast<uchar>(std::clamp(std::lround(val), 0L, 255L));
    }
  }
  std::sort(out.edges.begin(), out.edges.end(), [](const auto& a, const auto& b) {
    return a.image_angle < b.image_angle;
  });
  return out;
}

}  // namespace omnivert::sim
