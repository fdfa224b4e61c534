#pragma once
// A synthetic sequence of vertical lines for the tracker's tests: world lines with a
// descriptor and a bearing over time, and the frames of features that show them.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert::tracker_testing {

// A unit, non-negative, clipped descriptor like the paper's (Sec. 3.3).
inline Eigen::RowVectorXf random_descriptor(std::mt19937& rng, int dim = kPaperDescriptorSize) {
  std::exponential_distribution<float> e(1.0f);
  Eigen::RowVectorXf d(dim);
  for (int k = 0; k < dim; ++k) d(k) = e(rng);
  d.normalize();
  d = d.cwiseMin(0.1f);
  d.normalize();
  return d;
}

inline Eigen::RowVectorXf perturb(const Eigen::RowVectorXf& d, float sigma, std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, sigma);
  Eigen::RowVectorXf p = d;
  for (int k = 0; k < p.size(); ++k) p(k) = std::max(0.0f, p(k) + n(rng));
  p.normalize();
  return p;
}

// A unit vector at distance `dist` from the unit vector d, in the direction of q (made
// orthogonal to d): |p - d| = 2 sin(a / 2).
inline Eigen::RowVectorXf at_distance(const Eigen::RowVectorXf& d,
                                      Eigen::RowVectorXf q,
                                      double dist) {
  q -= q.dot(d) * d;
  q.normalize();
  const double a = 2.0 * std::asin(dist / 2.0);
  return (static_cast<float>(std::cos(a)) * d + static_cast<float>(std::sin(a)) * q).normalized();
}

// A world line of a synthetic sequence: its appearance, its bearing over time, and the frames
// in which it is seen.
struct SynthLine {
  Eigen::RowVectorXf descriptor;
  double bearing0 = 0.0;
  double rate = 0.0;  // radians per frame
  int first = 0;
  int last = 0;          // inclusive
  std::set<int> hidden;  // frames (within first..last) in which it is not detected
};

struct SynthFrame {
  FrameFeatures features;
  std::vector<int> world_ids;  // world line of each detected line
};

// Builds frame f: every visible line, in a shuffled order, with a noisy descriptor.
inline SynthFrame make_frame(const std::vector<SynthLine>& world,
                             int f,
                             float sigma,
                             std::mt19937& rng) {
  SynthFrame out;
  std::vector<int> visible;
  for (int w = 0; w < static_cast<int>(world.size()); ++w) {
    const SynthLine& l = world[static_cast<std::size_t>(w)];
    if (f >= l.first && f <= l.last && !l.hidden.count(f)) visible.push_back(w);
  }
  std::shuffle(visible.begin(), visible.end(), rng);
  out.features.descriptors.resize(static_cast<Eigen::Index>(visible.size()), kPaperDescriptorSize);
  for (std::size_t i = 0; i < visible.size(); ++i) {
    const SynthLine& l = world[static_cast<std::size_t>(visible[i])];
    VerticalLine v;
    v.bearing = wrap_angle(l.bearing0 + l.rate * f);
    v.image_angle = v.bearing;
    out.features.lines.push_back(v);
    out.features.descriptors.row(static_cast<Eigen::Index>(i)) = perturb(l.descriptor, sigma, rng);
    out.world_ids.push_back(visible[i]);
  }
  return out;
}

inline std::vector<SynthLine> make_world(int n, int frames, std::mt19937& rng) {
  std::vector<SynthLine> w(static_cast<std::size_t>(n));
  std::uniform_real_distribution<double> b(-kPi, kPi), r(-0.02, 0.02);
  for (auto& l : w) {
    l.descriptor = random_descriptor(rng);
    l.bearing0 = b(rng);
    l.rate = r(rng);
    l.first = 0;
    l.last = frames - 1;
  }
  return w;
}

// Runs a sequence; returns, per frame, the track id of each world line seen (world -> id).
inline std::vector<std::map<int, std::int64_t>> run(Tracker& tracker,
                                                    const std::vector<SynthLine>& world,
                                                    int frames,
                                                    float sigma,
                                                    std::mt19937& rng) {
  std::vector<std::map<int, std::int64_t>> ids(static_cast<std::size_t>(frames));
  std::vector<TrackAssignment> out;
  for (int f = 0; f < frames; ++f) {
    const SynthFrame fr = make_frame(world, f, sigma, rng);
    tracker.add_frame(fr.features, &out);
    EXPECT_EQ(out.size(), fr.world_ids.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
      ids[static_cast<std::size_t>(f)][fr.world_ids[i]] = out[i].track_id;
    }
  }
  return ids;
}

}  // namespace omnivert::tracker_testing
