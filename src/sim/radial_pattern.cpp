#include "omnivert/sim/radial_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "omnivert/core/angles.hpp"

namespace omnivert::sim {

namespace {

using Rng = std::mt19937_64;
using Uniform = std::uniform_real_distribution<double>;

struct Patch {
  double a0, a1;  // angular interval (a0 < a1, both in [0, 2 pi))
  double r0, r1;
  double level;
};

struct Blob {
  double x, y, sigma, amplitude;
};

// The unrotated scene: sectors between the sorted boundaries `bounds` (sector k spans
// [bounds[k], bounds[k+1])), patches on top, inside the rim and outside the disc.
struct Scene {
  double cx = 0, cy = 0;
  double rim_radius = 0, r_disc = 0;
  double rot = 0;  // the scene is rotated by this about the centre
  std::vector<double> bounds;
  std::vector<double> level;  // of each sector
  std::vector<Patch> patches;

  int sector_of(double a) const {
    // a in [0, 2 pi)
    auto it = std::upper_bound(bounds.begin(), bounds.end(), a);
    int k = static_cast<int>(it - bounds.begin()) - 1;
    return k < 0 ? static_cast<int>(bounds.size()) - 1 : k;
  }
  // Grey level at image point (x, y): the unrotated scene at angle - rotation.
  double value(double x, double y) const {
    const double dx = x - cx, dy = y - cy;
    const double r = std::sqrt(dx * dx + dy * dy);
    if (r > rim_radius) return 12.0;
    if (r < r_disc) return 25.0;
    const double a = wrap_positive(std::atan2(dy, dx) - rot);
    for (const Patch& p : patches)
      if (a >= p.a0 && a < p.a1 && r >= p.r0 && r < p.r1) return p.level;
    return level[sector_of(a)];
  }
  // Which region a point is in, to find the pixels that a boundary crosses.
  int region(double x, double y) const {
    const double dx = x - cx, dy = y - cy;
    const double r = std::sqrt(dx * dx + dy * dy);
    if (r > rim_radius) return -1;
    if (r < r_disc) return -2;
    const double a = wrap_positive(std::atan2(dy, dx) - rot);
    for (std::size_t i = 0; i < patches.size(); ++i) {
      const Patch& p = patches[i];
      if (a >= p.a0 && a < p.a1 && r >= p.r0 && r < p.r1) return 1000 + static_cast<int>(i);
    }
    return sector_of(a);
  }
};

// Sector boundaries with a minimum separation (rejection sampling), sorted.
std::vector<double> draw_sector_bounds(const RadialPatternOptions& o,
                                       double sep,
                                       Uniform& U,
                                       Rng& rng) {
  std::vector<double> bounds;
  for (int tries = 0; static_cast<int>(bounds.size()) < o.full_edges && tries < 10000; ++tries) {
    const double a = U(rng) * kTwoPi;
    bool ok = true;
    for (double b : bounds) ok = ok && std::abs(angle_diff(a, b)) >= 3 * sep;
    if (ok) bounds.push_back(a);
  }
  std::sort(bounds.begin(), bounds.end());
  return bounds;
}

// Grey levels of the sectors, with the required contrast between neighbours.
std::vector<double> draw_sector_levels(const RadialPatternOptions& o,
                                       int ns,
                                       Uniform& U,
                                       Rng& rng) {
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
  return level;
}

// Patches inside one sector, away from its boundaries and from each other; their edges are
// added to `edges`.
std::vector<Patch> draw_patches(const RadialPatternOptions& o,
                                const Scene& scene,
                                double sep,
                                std::vector<RadialEdgeTruth>& edges,
                                Uniform& U,
                                Rng& rng) {
  std::vector<Patch> patches;
  for (int tries = 0; static_cast<int>(patches.size()) < o.patches && tries < 10000; ++tries) {
    const double a0 = U(rng) * kTwoPi;
    const double width = deg2rad(6 + 20 * U(rng));
    const double a1 = a0 + width;
    bool ok = a1 < kTwoPi;
    for (const auto& e : edges) {
      ok = ok && std::abs(angle_diff(a0, e.image_angle)) >= sep &&
           std::abs(angle_diff(a1, e.image_angle)) >= sep;
    }
    if (ok) {
      // Not across a sector boundary.
      const int k0 = scene.sector_of(a0), k1 = scene.sector_of(std::fmod(a1, kTwoPi));
      ok = k0 == k1;
      for (double b : scene.bounds) ok = ok && !(b > a0 && b < a1);
    }
    for (const auto& p : patches) ok = ok && (a1 + sep < p.a0 || a0 > p.a1 + sep);
    if (!ok) continue;
    const double L = o.r_max - o.r_min;
    const double frac = 0.25 + 0.7 * U(rng);
    const double r0 = o.r_min + (1 - frac) * L * U(rng);
    const double r1 = r0 + frac * L;
    const double base = scene.level[scene.sector_of(a0)];
    const double c = o.min_contrast + (o.max_contrast - o.min_contrast) * U(rng);
    const double lv = (base + c <= 235 && (base - c < 20 || U(rng) < 0.5)) ? base + c : base - c;
    patches.push_back({a0, a1, r0, r1, lv});
    edges.push_back({wrap_angle(a0), r0, r1, false});
    edges.push_back({wrap_angle(a1), r0, r1, false});
  }
  return patches;
}

// Low-contrast blobs in the annulus (unrotated scene), so descriptors differ between lines.
std::vector<Blob> draw_blobs(
    const RadialPatternOptions& o, double cx, double cy, Uniform& U, Rng& rng) {
  std::vector<Blob> blobs;
  if (!o.texture) return blobs;
  for (int i = 0; i < 60; ++i) {
    const double r = o.r_min + (o.r_max - o.r_min) * U(rng);
    const double a = U(rng) * kTwoPi;
    blobs.push_back(
        {cx + r * std::cos(a), cy + r * std::sin(a), 4 + 10 * U(rng), (2 * U(rng) - 1) * 12});
  }
  return blobs;
}

// The scene's grey levels, 8 x 8 supersampled where a boundary crosses the pixel.
cv::Mat render_scene(const Scene& scene, int width, int height) {
  cv::Mat img(height, width, CV_32F);
  const int ss = 8;
  for (int v = 0; v < height; ++v) {
    float* row = img.ptr<float>(v);
    for (int u = 0; u < width; ++u) {
      // A pixel is uniform if its centre and a ring of points at its border agree.
      const int r0 = scene.region(u, v);
      bool uniform = true;
      for (int k = 0; k < 8 && uniform; ++k) {
        const double a = k * kPi / 4;
        uniform = scene.region(u + 0.75 * std::cos(a), v + 0.75 * std::sin(a)) == r0;
      }
      double val;
      if (uniform) {
        val = scene.value(u, v);
      } else {
        double acc = 0;
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i)
            acc += scene.value(u - 0.5 + (i + 0.5) / ss, v - 0.5 + (j + 0.5) / ss);
        val = acc / (ss * ss);
      }
      row[u] = static_cast<float>(val);
    }
  }
  return img;
}

// Smooth texture, added to every pixel inside the mirror.
void add_texture(cv::Mat& img, const Scene& scene, const std::vector<Blob>& blobs) {
  for (int v = 0; v < img.rows; ++v) {
    float* row = img.ptr<float>(v);
    for (int u = 0; u < img.cols; ++u) {
      const double dx = u - scene.cx, dy = v - scene.cy;
      const double r = std::sqrt(dx * dx + dy * dy);
      if (r > scene.rim_radius - 1 || r < scene.r_disc + 1) continue;
      double t = 0;
      for (const Blob& b : blobs) {
        const double ex = u - b.x, ey = v - b.y;
        const double d2 = ex * ex + ey * ey;
        if (d2 < 9 * b.sigma * b.sigma) t += b.amplitude * std::exp(-d2 / (2 * b.sigma * b.sigma));
      }
      row[u] += static_cast<float>(t);
    }
  }
}

// Gaussian image noise and rounding to 8 bits.
void quantize_with_noise(const cv::Mat& img,
                         const RadialPatternOptions& o,
                         Rng& rng,
                         cv::Mat& out) {
  std::normal_distribution<double> N(0.0, o.noise_sigma);
  out.create(img.rows, img.cols, CV_8U);
  for (int v = 0; v < img.rows; ++v) {
    const float* src = img.ptr<float>(v);
    uchar* dst = out.ptr<uchar>(v);
    for (int u = 0; u < img.cols; ++u) {
      const double val = src[u] + (o.noise_sigma > 0 ? N(rng) : 0.0);
      dst[u] = static_cast<uchar>(std::clamp(std::lround(val), 0L, 255L));
    }
  }
}

}  // namespace

RadialPattern draw_radial_pattern(const RadialPatternOptions& o) {
  Rng rng(o.seed);
  Uniform U(0.0, 1.0);
  RadialPattern out;
  Scene scene;
  scene.cx = (o.width - 1) / 2.0 + (2 * U(rng) - 1) * o.center_jitter;
  scene.cy = (o.height - 1) / 2.0 + (2 * U(rng) - 1) * o.center_jitter;
  out.circle.center = {scene.cx, scene.cy};
  out.circle.r_min = o.r_min;
  out.circle.r_max = o.r_max;
  out.circle.rim_radius = o.rim_radius;
  const double sep = deg2rad(o.min_separation_deg);

  scene.bounds = draw_sector_bounds(o, sep, U, rng);
  scene.level = draw_sector_levels(o, static_cast<int>(scene.bounds.size()), U, rng);
  for (double b : scene.bounds) out.edges.push_back({wrap_angle(b), o.r_min, o.r_max, true});
  scene.patches = draw_patches(o, scene, sep, out.edges, U, rng);
  std::vector<Blob> blobs = draw_blobs(o, scene.cx, scene.cy, U, rng);

  // Rotation of the scene: evaluate the unrotated scene at angle - rotation.
  scene.rot = o.rotation_rad;
  const double cr = std::cos(scene.rot), sr = std::sin(scene.rot);
  for (Blob& b : blobs) {
    const double bx = b.x - scene.cx, by = b.y - scene.cy;
    b.x = scene.cx + cr * bx - sr * by;
    b.y = scene.cy + sr * bx + cr * by;
  }
  for (auto& e : out.edges) e.image_angle = wrap_angle(e.image_angle + scene.rot);
  scene.rim_radius = o.rim_radius;
  scene.r_disc = o.r_min / 1.1;

  cv::Mat img = render_scene(scene, o.width, o.height);
  if (!blobs.empty()) add_texture(img, scene, blobs);
  if (o.noise_seed != 0) rng.seed(o.noise_seed);
  quantize_with_noise(img, o, rng, out.image);
  std::sort(out.edges.begin(), out.edges.end(), [](const auto& a, const auto& b) {
    return a.image_angle < b.image_angle;
  });
  return out;
}

}  // namespace omnivert::sim
