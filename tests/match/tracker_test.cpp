#include "omnivert/match/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {
namespace {

// A unit, non-negative, clipped descriptor like the paper's (Sec. 3.3).
Eigen::RowVectorXf random_descriptor(std::mt19937& rng, int dim = kPaperDescriptorSize) {
  std::exponential_distribution<float> e(1.0f);
  Eigen::RowVectorXf d(dim);
  for (int k = 0; k < dim; ++k) d(k) = e(rng);
  d.normalize();
  d = d.cwiseMin(0.1f);
  d.normalize();
  return d;
}

Eigen::RowVectorXf perturb(const Eigen::RowVectorXf& d, float sigma, std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, sigma);
  Eigen::RowVectorXf p = d;
  for (int k = 0; k < p.size(); ++k) p(k) = std::max(0.0f, p(k) + n(rng));
  p.normalize();
  return p;
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
SynthFrame make_frame(const std::vector<SynthLine>& world, int f, float sigma, std::mt19937& rng) {
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

std::vector<SynthLine> make_world(int n, int frames, std::mt19937& rng) {
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
std::vector<std::map<int, std::int64_t>> run(Tracker& tracker,
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

TEST(TrackerOptions, Validation) {
  std::string error;
  EXPECT_TRUE(TrackerOptions{}.IsValid(&error));
  TrackerOptions o;
  o.look_back = 0;
  EXPECT_FALSE(o.IsValid(&error));
  o = {};
  o.gate.enabled = true;  // wheel base missing
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("wheel base"), std::string::npos);
  o.gate.wheel_base = 0.4;
  EXPECT_TRUE(o.IsValid(&error));
}

TEST(Tracker, IdsPreservedOverASequence) {
  std::mt19937 rng(11);
  const int frames = 60;
  const auto world = make_world(30, frames, rng);
  for (bool mutual : {false, true}) {
    TrackerOptions o;
    o.mutual = mutual;
    Tracker tracker(o);
    const auto ids = run(tracker, world, frames, 0.01f, rng);
    // Every world line keeps the id it got in frame 0, and ids are 0..29.
    std::set<std::int64_t> seen;
    for (int w = 0; w < 30; ++w) {
      const std::int64_t id0 = ids[0].at(w);
      seen.insert(id0);
      for (int f = 1; f < frames; ++f) {
        ASSERT_EQ(ids[static_cast<std::size_t>(f)].at(w), id0) << "line " << w << " frame " << f;
      }
    }
    EXPECT_EQ(seen.size(), 30u);
    EXPECT_EQ(*seen.rbegin(), 29);
    EXPECT_EQ(tracker.tracks_created(), 30);
    EXPECT_EQ(tracker.stats().matched_previous, 30 * (frames - 1));
    EXPECT_EQ(tracker.stats().matched_look_back, 0);
  }
}

TEST(Tracker, LookBackRecoversDropoutsAndNewLinesGetNewIds) {
  std::mt19937 rng(23);
  const int frames = 80;
  auto world = make_world(25, frames, rng);
  // Line 3 is missed for 5 frames, line 7 for 19 frames (back in frame 50: 20 frames back).
  for (int f = 10; f < 15; ++f) world[3].hidden.insert(f);
  for (int f = 31; f < 50; ++f) world[7].hidden.insert(f);
  // Line 9 is missed for 25 frames: beyond the look-back, it must come back as a new track.
  for (int f = 20; f < 45; ++f) world[9].hidden.insert(f);
  // Lines 20-24 vanish at frame 40; 5 new lines appear at frame 41.
  for (int w = 20; w < 25; ++w) world[static_cast<std::size_t>(w)].last = 39;
  std::mt19937 rng2(99);
  for (int k = 0; k < 5; ++k) {
    SynthLine l;
    l.descriptor = random_descriptor(rng2);
    l.bearing0 = -3.0 + k;
    l.first = 41;
    l.last = frames - 1;
    world.push_back(l);
  }

  Tracker tracker{TrackerOptions{}};
  const auto ids = run(tracker, world, frames, 0.01f, rng);
  EXPECT_EQ(ids[15].at(3), ids[9].at(3));   // 6 frames back
  EXPECT_EQ(ids[50].at(7), ids[30].at(7));  // 20 frames back: the limit, still found
  EXPECT_NE(ids[45].at(9), ids[19].at(9));  // 26 frames back: a new id
  EXPECT_EQ(ids[45].at(9), ids[79].at(9));  // and then tracked under it
  std::set<std::int64_t> fresh;
  for (int w = 25; w < 30; ++w) {
    const std::int64_t id = ids[41].at(w);
    EXPECT_GE(id, 25);  // never an id of an earlier line
    fresh.insert(id);
    EXPECT_EQ(ids[79].at(w), id);
  }
  EXPECT_EQ(fresh.size(), 5u);
  // 25 initial + 5 new + line 9's second life.
  EXPECT_EQ(tracker.tracks_created(), 31);
  EXPECT_EQ(tracker.stats().matched_look_back, 2);

  // With a look-back of 3 frames, line 3's 5-frame gap is too long: a new id.
  std::mt19937 rng3(23);
  TrackerOptions short_o;
  short_o.look_back = 3;
  Tracker short_tracker(short_o);
  const auto ids3 = run(short_tracker, world, frames, 0.01f, rng3);
  EXPECT_NE(ids3[15].at(3), ids3[9].at(3));
}

// A frame with no lines (e.g. an unreadable image) counts as a frame for the look-back.
TEST(Tracker, EmptyFramesCountTowardsLookBack) {
  std::mt19937 rng(5);
  const auto world = make_world(10, 1, rng);
  TrackerOptions o;
  o.look_back = 4;
  Tracker tracker(o);
  std::vector<TrackAssignment> out;
  const SynthFrame f0 = make_frame(world, 0, 0.01f, rng);
  tracker.add_frame(f0.features, &out);
  const std::int64_t id_first = out[0].track_id;
  const int w_first = f0.world_ids[0];
  FrameFeatures empty;
  for (int k = 0; k < 3; ++k) {
    tracker.add_frame(empty, &out);
    EXPECT_TRUE(out.empty());
  }
  SynthFrame f4 = make_frame(world, 0, 0.01f, rng);  // 4 frames after f0: within reach
  tracker.add_frame(f4.features, &out);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (f4.world_ids[i] == w_first) {
      EXPECT_EQ(out[i].track_id, id_first);
      EXPECT_EQ(out[i].frames_back, 4);
    }
  }
  EXPECT_EQ(tracker.frames_seen(), 5);
}

// Two lines of the new frame both nearest to one line of the previous frame: the paper's
// rules give both the same id; the mutual constraint keeps it for the nearer one only.
TEST(Tracker, MutualConstraintRemovesDoubleClaim) {
  std::mt19937 rng(3);
  std::vector<Eigen::RowVectorXf> base;
  for (int k = 0; k < 8; ++k) base.push_back(random_descriptor(rng));
  FrameFeatures prev;
  prev.descriptors.resize(8, kPaperDescriptorSize);
  for (int k = 0; k < 8; ++k) {
    prev.descriptors.row(k) = base[static_cast<std::size_t>(k)];
    prev.lines.push_back(VerticalLine{});
  }
  FrameFeatures now = prev;
  // Lines 0 and 1 of the new frame both look like line 0 of the previous frame; line 1 is the
  // farther of the two. Line 1's own old appearance is replaced (it is gone).
  now.descriptors.row(0) = perturb(base[0], 0.003f, rng);
  now.descriptors.row(1) = perturb(base[0], 0.012f, rng);
  const float d0 = (now.descriptors.row(0) - prev.descriptors.row(0)).norm();
  const float d1 = (now.descriptors.row(1) - prev.descriptors.row(0)).norm();
  ASSERT_LT(d0, d1);

  for (bool mutual : {false, true}) {
    TrackerOptions o;
    o.mutual = mutual;
    Tracker tracker(o);
    std::vector<TrackAssignment> out;
    tracker.add_frame(prev, &out);
    const std::int64_t id0 = out[0].track_id;
    tracker.add_frame(now, &out);
    EXPECT_EQ(out[0].track_id, id0);
    if (!mutual) {
      EXPECT_EQ(out[1].track_id, id0);  // the double claim
      EXPECT_EQ(tracker.stats().rejected_mutual, 0);
    } else {
      EXPECT_NE(out[1].track_id, id0);
      EXPECT_TRUE(out[1].is_new());
      EXPECT_EQ(tracker.stats().rejected_mutual, 1);
    }
    for (int k = 2; k < 8; ++k) EXPECT_EQ(out[static_cast<std::size_t>(k)].frames_back, 1);
  }
}

// With mutual on, a track taken in a recent frame cannot be claimed again through look-back.
TEST(Tracker, MutualTrackClaimedOnceAcrossLookBack) {
  std::mt19937 rng(31);
  std::vector<Eigen::RowVectorXf> base;
  for (int k = 0; k < 6; ++k) base.push_back(random_descriptor(rng));
  auto frame_of = [&](const std::vector<Eigen::RowVectorXf>& rows) {
    FrameFeatures f;
    f.descriptors.resize(static_cast<Eigen::Index>(rows.size()), kPaperDescriptorSize);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      f.descriptors.row(static_cast<Eigen::Index>(i)) = rows[i];
      f.lines.push_back(VerticalLine{});
    }
    return f;
  };
  // Frame 0: appearance X of line 0 (and others). Frame 1: appearance Y of line 0 (changed).
  // Frame 2: both X (a lookalike) and Y. Y matches frame 1; X fails in frame 1 (nearest is Y'
  // of track 0, but Y is its mutual nearest) and reaches frame 0, where track 0 is taken.
  const Eigen::RowVectorXf x = base[0];
  const Eigen::RowVectorXf y = perturb(base[0], 0.02f, rng);
  std::vector<Eigen::RowVectorXf> f0 = {x, base[1], base[2], base[3], base[4], base[5]};
  std::vector<Eigen::RowVectorXf> f1 = {y, base[1], base[2], base[3], base[4], base[5]};
  std::vector<Eigen::RowVectorXf> f2 = {perturb(y, 0.002f, rng),
                                        perturb(x, 0.002f, rng),
                                        base[1],
                                        base[2],
                                        base[3],
                                        base[4],
                                        base[5]};
  TrackerOptions o;
  o.mutual = true;
  Tracker tracker(o);
  std::vector<TrackAssignment> out;
  tracker.add_frame(frame_of(f0), &out);
  const std::int64_t id0 = out[0].track_id;
  tracker.add_frame(frame_of(f1), &out);
  ASSERT_EQ(out[0].track_id, id0);
  tracker.add_frame(frame_of(f2), &out);
  EXPECT_EQ(out[0].track_id, id0);
  EXPECT_EQ(out[0].frames_back, 1);
  EXPECT_TRUE(out[1].is_new());
  EXPECT_GE(tracker.stats().rejected_claimed, 1);
  std::set<std::int64_t> ids;
  for (const auto& a : out) EXPECT_TRUE(ids.insert(a.track_id).second) << "duplicate id";
}

TEST(BearingGate, IncrementFromCumulativeTravel) {
  const WheelIncrement inc = increment_between(1.0, 2.0, 1.25, 2.5);
  EXPECT_DOUBLE_EQ(inc.d_left, 0.25);
  EXPECT_DOUBLE_EQ(inc.d_right, 0.5);
}

TEST(BearingGate, PureRotationAndTranslationBounds) {
  OdometryGateOptions o;
  o.enabled = true;
  o.wheel_base = 0.4;
  o.min_feature_distance = 0.5;
  o.max_camera_offset = 0.2;
  o.bearing_tolerance = 0.0;
  o.slip_fraction = 0.0;
  OdometryAccumulator a, b;
  b.add({0.04, -0.04}, o.wheel_base);  // turn on the spot by 0.2 rad
  BearingGate g = make_bearing_gate(o, a, b);
  EXPECT_NEAR(g.predicted_change, -0.2, 1e-12);
  EXPECT_NEAR(g.max_deviation, std::asin(2 * 0.2 * std::sin(0.1) / 0.5), 1e-12);
  EXPECT_TRUE(g.admits(1.0, 0.8));
  EXPECT_FALSE(g.admits(1.0, 1.0));
  // Across the wrap: 3.1 - 0.2 -> 2.9; -3.1 - 0.2 -> wraps to +2.98.
  EXPECT_TRUE(g.admits(-3.1, wrap_angle(-3.3)));
  // Straight 0.6 m: farther than D_min, nothing can be said.
  OdometryAccumulator c;
  c.add({0.6, 0.6}, o.wheel_base);
  g = make_bearing_gate(o, a, c);
  EXPECT_FALSE(g.informative);
  EXPECT_TRUE(g.admits(0.0, 3.0));
  // Slip and tolerance widen the gate.
  o.bearing_tolerance = 0.01;
  o.slip_fraction = 0.05;
  g = make_bearing_gate(o, a, b);
  EXPECT_NEAR(
      g.max_deviation, std::asin(2 * 0.2 * std::sin(0.1) / 0.5) + 0.05 * 0.08 / 0.4 + 0.01, 1e-12);
}

// Soundness: for random extrinsics (rho <= rho_max), random drives and random static lines at
// least D_min from the camera at both frames, the true bearing change (eqs. 16-17) always
// lies inside the gate with zero tolerance and zero slip.
TEST(BearingGate, TrueBearingChangesAlwaysAdmitted) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  OdometryGateOptions o;
  o.enabled = true;
  o.wheel_base = 0.4;
  o.min_feature_distance = 0.8;
  o.max_camera_offset = 0.3;
  o.bearing_tolerance = 0.0;
  o.slip_fraction = 0.0;
  int informative = 0, tight = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double phi = kPi * u(rng), psi = kPi * u(rng);
    const double rho = 0.3 * std::abs(u(rng));
    double x = 0, y = 0, th = kPi * u(rng);
    auto camera = [&](double& cx, double& cy) {
      cx = x + rho * std::cos(th + phi);
      cy = y + rho * std::sin(th + phi);
    };
    auto bearing = [&](double fx, double fy) {  // eq. (16)
      double cx, cy;
      camera(cx, cy);
      return wrap_angle(std::atan2(fy - cy, fx - cx) - (th + phi + psi));
    };
    // A static line 0.8-3 m from the start.
    double c0x, c0y;
    camera(c0x, c0y);
    const double r0 = 0.8 + 2.2 * std::abs(u(rng)), a0 = kPi * u(rng);
    const double fx = c0x + r0 * std::cos(a0), fy = c0y + r0 * std::sin(a0);
    const double b0 = bearing(fx, fy);
    OdometryAccumulator before, after;
    const int steps = 1 + static_cast<int>(10 * std::abs(u(rng)));
    for (int s = 0; s < steps; ++s) {
      const WheelIncrement inc{0.05 * u(rng), 0.05 * u(rng)};
      after.add(inc, o.wheel_base);
      // Differential drive, integrated in sub-steps (exact arcs in the limit).
      for (int k = 0; k < 20; ++k) {
        const double dr = 0.5 * (inc.d_right + inc.d_left) / 20,
                     dt = (inc.d_right - inc.d_left) / o.wheel_base / 20;
        x += dr * std::cos(th + dt / 2);
        y += dr * std::sin(th + dt / 2);
        th += dt;
      }
    }
    double c1x, c1y;
    camera(c1x, c1y);
    if (std::hypot(fx - c1x, fy - c1y) < o.min_feature_distance) continue;
    const BearingGate g = make_bearing_gate(o, before, after);
    const double b1 = bearing(fx, fy);
    ASSERT_TRUE(g.admits(b0, b1)) << "trial " << trial << " deviation "
                                  << angle_diff(b1, b0 + g.predicted_change) << " bound "
                                  << g.max_deviation;
    informative += g.informative;
    if (g.informative &&
        std::abs(angle_diff(b1, b0 + g.predicted_change)) > 0.5 * g.max_deviation) {
      ++tight;
    }
  }
  EXPECT_GT(informative, 10000);
  EXPECT_GT(tight, 100);  // the bound is reached in part, not vacuously loose
}

// A constructed false match: the nearest descriptor sits at an impossible bearing.
TEST(Tracker, OdometryGateRejectsImpossibleBearingJump) {
  std::mt19937 rng(41);
  FrameFeatures f0;
  f0.descriptors.resize(6, kPaperDescriptorSize);
  for (int k = 0; k < 6; ++k) {
    f0.descriptors.row(k) = random_descriptor(rng);
    VerticalLine v;
    v.bearing = -2.5 + k;
    f0.lines.push_back(v);
  }
  // The robot turns by d_theta = (0.03 + 0.03) / 0.4 = 0.15 rad: bearings shift by -0.15.
  const WheelIncrement turn{0.03, -0.03};
  FrameFeatures f1 = f0;
  for (int k = 0; k < 6; ++k) {
    f1.descriptors.row(k) = perturb(f0.descriptors.row(k), 0.005f, rng);
    f1.lines[static_cast<std::size_t>(k)].bearing = wrap_angle(f0.lines[k].bearing - 0.15);
  }
  // Line 2 of the new frame looks like line 2 but is 1 rad away from where it can be.
  f1.lines[2].bearing = wrap_angle(f0.lines[2].bearing - 0.15 + 1.0);

  for (bool gate : {false, true}) {
    TrackerOptions o;
    o.gate.enabled = gate;
    o.gate.wheel_base = 0.4;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out1;
    tracker.add_frame(f0, WheelIncrement{}, &out0);
    tracker.add_frame(f1, turn, &out1);
    for (int k = 0; k < 6; ++k) {
      if (k == 2) continue;
      EXPECT_EQ(out1[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    }
    if (gate) {
      EXPECT_TRUE(out1[2].is_new());
      EXPECT_EQ(tracker.stats().rejected_gate, 1);
    } else {
      EXPECT_EQ(out1[2].track_id, out0[2].track_id);
    }
  }
}

// Two look-alike lines (a repeated door frame) 1 rad apart: in the next frame the true line
// fails test 3 against its twin (and starts a new track) unless the candidates are restricted
// to those the odometry gate admits (gate_candidates), where the twin is not one of them.
TEST(Tracker, GateCandidatesResolveLookAlikes) {
  std::mt19937 rng(43);
  FrameFeatures f0;
  f0.descriptors.resize(6, kPaperDescriptorSize);
  for (int k = 0; k < 6; ++k) {
    f0.descriptors.row(k) = random_descriptor(rng);
    VerticalLine v;
    v.bearing = -2.5 + k;
    f0.lines.push_back(v);
  }
  f0.descriptors.row(3) = perturb(f0.descriptors.row(2), 0.0005f, rng);  // 2's twin
  const WheelIncrement turn{0.03, -0.03};  // bearings shift by -0.15 rad
  FrameFeatures f1 = f0;
  for (int k = 0; k < 6; ++k) {
    f1.descriptors.row(k) = perturb(f0.descriptors.row(k), 0.004f, rng);
    f1.lines[static_cast<std::size_t>(k)].bearing = wrap_angle(f0.lines[k].bearing - 0.15);
  }
  for (bool restrict : {false, true}) {
    TrackerOptions o = recommended_tracker_options(0.4);
    o.gate_candidates = restrict;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out1;
    tracker.add_frame(f0, WheelIncrement{}, &out0);
    tracker.add_frame(f1, turn, &out1);
    for (int k : {0, 1, 4, 5})
      EXPECT_EQ(out1[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    for (int k : {2, 3}) {
      if (restrict) {
        EXPECT_EQ(out1[static_cast<std::size_t>(k)].track_id, out0[k].track_id) << k;
      } else {
        EXPECT_TRUE(out1[static_cast<std::size_t>(k)].is_new()) << k;  // test 3 fails
      }
    }
    EXPECT_EQ(tracker.stats().rejected_test3, restrict ? 0 : 2);
  }
}

// The other side of a door frame (opposite polarity, a look-alike descriptor) seen where the
// first side was: linked by the paper's rules, a new track with same_polarity; lines of
// unknown polarity (0) are not constrained.
TEST(Tracker, SamePolarityKeepsOppositeEdgesApart) {
  std::mt19937 rng(47);
  FrameFeatures f0;
  f0.descriptors.resize(6, kPaperDescriptorSize);
  for (int k = 0; k < 6; ++k) {
    f0.descriptors.row(k) = random_descriptor(rng);
    VerticalLine v;
    v.bearing = -2.5 + k;
    v.polarity = k % 2 ? 1 : -1;
    f0.lines.push_back(v);
  }
  FrameFeatures f1 = f0;
  for (int k = 0; k < 6; ++k) f1.descriptors.row(k) = perturb(f0.descriptors.row(k), 0.004f, rng);
  f1.lines[2].polarity = -f0.lines[2].polarity;  // the frame's other side
  f1.descriptors.row(2) = perturb(f0.descriptors.row(2), 0.02f, rng);
  for (int unknown : {0, 1}) {
    for (bool same : {false, true}) {
      TrackerOptions o;
      o.same_polarity = same;
      Tracker tracker(o);
      FrameFeatures g0 = f0, g1 = f1;
      if (unknown) g1.lines[2].polarity = 0;
      std::vector<TrackAssignment> out0, out1;
      tracker.add_frame(g0, &out0);
      tracker.add_frame(g1, &out1);
      for (int k : {0, 1, 3, 4, 5})
        EXPECT_EQ(out1[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
      if (same && !unknown) {
        EXPECT_TRUE(out1[2].is_new());
      } else {
        EXPECT_EQ(out1[2].track_id, out0[2].track_id);
      }
    }
  }
}

// Driving straight, line 2 drifts by 0.2 degree a frame (parallax); in frame 3 extraction finds
// its neighbour edge instead, 1.3 degrees off the predicted bearing. Continuity refuses that
// link (a new track); the true continuation of every other line is kept.
TEST(Tracker, ContinuityRefusesAJumpToTheNeighbourEdge) {
  std::mt19937 rng(53);
  const double deg = kPi / 180.0;
  std::vector<Eigen::RowVectorXf> d;
  for (int k = 0; k < 6; ++k) d.push_back(random_descriptor(rng));
  auto frame = [&](int f, bool neighbour) {
    FrameFeatures fr;
    fr.descriptors.resize(6, kPaperDescriptorSize);
    for (int k = 0; k < 6; ++k) {
      VerticalLine v;
      v.bearing = -2.5 + k + (k == 2 ? 0.2 * deg * f : 0.0);
      fr.descriptors.row(k) = perturb(d[static_cast<std::size_t>(k)], 0.004f, rng);
      if (k == 2 && neighbour) {
        v.bearing += 1.3 * deg;
        fr.descriptors.row(k) = perturb(d[2], 0.02f, rng);
      }
      fr.lines.push_back(v);
    }
    return fr;
  };
  const WheelIncrement straight{0.038, 0.038};
  for (double tol : {0.0, 0.6 * deg}) {
    TrackerOptions o = recommended_tracker_options(0.4);
    o.continuity_tolerance = tol;
    // Frame 0 has no history before it: a link to it would not be checked, so the look-back
    // stops before it.
    o.look_back = 2;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out;
    tracker.add_frame(frame(0, false), WheelIncrement{}, &out0);
    for (int f = 1; f <= 2; ++f) {
      tracker.add_frame(frame(f, false), straight, &out);
      for (int k = 0; k < 6; ++k)
        EXPECT_EQ(out[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    }
    tracker.add_frame(frame(3, true), straight, &out);
    for (int k : {0, 1, 3, 4, 5})
      EXPECT_EQ(out[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    if (tol > 0.0) {
      EXPECT_TRUE(out[2].is_new());
      EXPECT_GE(tracker.stats().rejected_continuity, 1);
    } else {
      EXPECT_EQ(out[2].track_id, out0[2].track_id);
    }
  }
}

// A unit vector at distance `dist` from the unit vector d, in the direction of q (made
// orthogonal to d): |p - d| = 2 sin(a / 2).
Eigen::RowVectorXf at_distance(const Eigen::RowVectorXf& d, Eigen::RowVectorXf q, double dist) {
  q -= q.dot(d) * d;
  q.normalize();
  const double a = 2.0 * std::asin(dist / 2.0);
  return (static_cast<float>(std::cos(a)) * d + static_cast<float>(std::sin(a)) * q).normalized();
}

// Turning on the spot (0.1 rad a frame), line 2 drifts by 0.2 degree a frame beyond the
// rotation (the camera swings around the axle); in frame 4 extraction finds its neighbour edge
// instead, 2 degrees off. The link model of continuity takes no rate from a turn and allows the
// camera-swing bound (3.4 degrees a frame): it links the neighbour. The track model carries
// the rate per radian turned and refuses it (tolerance 0.8 + 0.17 degree one frame back,
// 0.8 + 0.69 two frames back): a new track. Every other line keeps its track in both.
TEST(Tracker, TrackModelContinuityRefusesAJumpDuringATurn) {
  const double deg = kPi / 180.0;
  const double e = 0.4;                                     // wheel base
  const WheelIncrement turn{0.05 * e, -0.05 * e};           // d_theta = 0.1 rad, no path
  for (auto model : {TrackerOptions::ContinuityModel::kLink,
                     TrackerOptions::ContinuityModel::kTrack}) {
    std::mt19937 rng(61);
    std::vector<Eigen::RowVectorXf> d;
    for (int k = 0; k < 6; ++k) d.push_back(random_descriptor(rng));
    auto frame = [&](int f, bool neighbour) {
      FrameFeatures fr;
      fr.descriptors.resize(6, kPaperDescriptorSize);
      for (int k = 0; k < 6; ++k) {
        VerticalLine v;
        // Bearings of static lines shift by -d_theta (eq. 16), plus line 2's swing parallax.
        v.bearing = wrap_angle(-2.5 + k - 0.1 * f + (k == 2 ? 0.2 * deg * f : 0.0));
        fr.descriptors.row(k) = perturb(d[static_cast<std::size_t>(k)], 0.004f, rng);
        if (k == 2 && neighbour) {
          v.bearing += 2.0 * deg;
          fr.descriptors.row(k) = perturb(d[2], 0.02f, rng);
        }
        fr.lines.push_back(v);
      }
      return fr;
    };
    TrackerOptions o = recommended_tracker_options(e);
    o.continuity_model = model;
    o.look_back = 2;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out;
    tracker.add_frame(frame(0, false), WheelIncrement{}, &out0);
    for (int f = 1; f <= 3; ++f) {
      tracker.add_frame(frame(f, false), turn, &out);
      for (int k = 0; k < 6; ++k) EXPECT_EQ(out[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    }
    tracker.add_frame(frame(4, true), turn, &out);
    for (int k : {0, 1, 3, 4, 5}) EXPECT_EQ(out[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    if (model == TrackerOptions::ContinuityModel::kTrack) {
      EXPECT_TRUE(out[2].is_new());
      EXPECT_EQ(tracker.stats().rejected_continuity, 2);  // one and two frames back
    } else {
      EXPECT_EQ(out[2].track_id, out0[2].track_id);
      EXPECT_EQ(out[2].frames_back, 1);
      EXPECT_EQ(tracker.stats().rejected_continuity, 0);
    }
  }
}

// Six lines; line 0 is missed in frame 1 and found in frame 2 at descriptor distance 0.45 from
// frame 0 (the other lines are farther). The paper's rules link it across the gap (tests 1-3 pass: 0.45 <=
// 1.05, <= 0.75 * mean, <= 0.8 * second); with look_back_f1 = 0.4 it starts a new track.
TEST(Tracker, LookBackF1RefusesADistantLinkAcrossAGap) {
  for (double lf1 : {0.0, 0.4}) {
    std::mt19937 rng(67);
    std::vector<Eigen::RowVectorXf> d;
    for (int k = 0; k < 6; ++k) d.push_back(random_descriptor(rng));
    const Eigen::RowVectorXf changed = at_distance(d[0], random_descriptor(rng), 0.45);
    auto frame = [&](bool with0, bool changed0) {
      FrameFeatures fr;
      for (int k = with0 ? 0 : 1; k < 6; ++k) {
        VerticalLine v;
        v.bearing = -2.5 + k;
        fr.lines.push_back(v);
      }
      fr.descriptors.resize(static_cast<Eigen::Index>(fr.lines.size()), kPaperDescriptorSize);
      for (int k = with0 ? 0 : 1, r = 0; k < 6; ++k, ++r) {
        fr.descriptors.row(r) = k == 0 && changed0 ? changed : d[static_cast<std::size_t>(k)];
      }
      return fr;
    };
    TrackerOptions o = paper_tracker_options();
    o.look_back_f1 = lf1;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out1, out2;
    tracker.add_frame(frame(true, false), &out0);
    tracker.add_frame(frame(false, false), &out1);
    tracker.add_frame(frame(true, true), &out2);
    for (int k = 1; k < 6; ++k) EXPECT_EQ(out2[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    if (lf1 > 0.0) {
      EXPECT_TRUE(out2[0].is_new());
      EXPECT_EQ(tracker.stats().rejected_test1, 1);
    } else {
      EXPECT_EQ(out2[0].track_id, out0[0].track_id);
      EXPECT_EQ(out2[0].frames_back, 2);
      EXPECT_NEAR(out2[0].distance, 0.45f, 1e-3f);
      EXPECT_EQ(tracker.stats().rejected_test1, 0);
    }
  }
}

// Confirmed F1: driving straight, line 2 drifts by 0.2 degree a frame (parallax); in frame 3
// its descriptor has changed to 0.48 from frame 2's, beyond F1 = 0.4 (tests 2 and 3 pass). Without
// the rule it is refused by test 1 (a new track, verdict kTest1 at frame t-1). With confirm_f1
// = 1.05 it is linked when its bearing is where the track predicts it (0.05 degree off, within
// 0.3), and still refused when it is 0.5 degree off (beyond 0.3, within continuity's 0.8), or when
// a second line of the new frame sits 0.6 degree from the prediction (ambiguous).
TEST(Tracker, ConfirmedF1LinksAChangedDescriptorWhereTheTrackPredictsIt) {
  const double deg = kPi / 180.0;
  struct Case {
    double cf1, off_deg;
    bool neighbour, linked;
  };
  for (const Case c : {Case{0.0, 0.05, false, false},
                       Case{1.05, 0.05, false, true},
                       Case{1.05, 0.5, false, false},
                       Case{1.05, 0.05, true, false}}) {
    std::mt19937 rng(59);
    std::vector<Eigen::RowVectorXf> d;
    for (int k = 0; k < 6; ++k) d.push_back(random_descriptor(rng));
    const Eigen::RowVectorXf changed = at_distance(d[2], random_descriptor(rng), 0.48);
    auto frame = [&](int f) {
      FrameFeatures fr;
      const bool last = f == 3;
      const int n = last && c.neighbour ? 7 : 6;
      fr.descriptors.resize(n, kPaperDescriptorSize);
      for (int k = 0; k < n; ++k) {
        VerticalLine v;
        if (k < 6) {
          v.bearing = -2.5 + k + (k == 2 ? 0.2 * deg * f + (last ? c.off_deg * deg : 0.0) : 0.0);
          fr.descriptors.row(k) =
              k == 2 && last ? changed : perturb(d[static_cast<std::size_t>(k)], 0.004f, rng);
        } else {  // a line far from line 2 in descriptor space, next to its prediction
          v.bearing = -2.5 + 2 + 0.2 * deg * f + 0.6 * deg;
          fr.descriptors.row(k) = random_descriptor(rng);
        }
        fr.lines.push_back(v);
      }
      return fr;
    };
    TrackerOptions o = recommended_tracker_options(0.4);
    o.look_back = 2;
    o.match.f1 = 0.4;
    o.look_back_f1 = 0.0;
    o.confirm_f1 = c.cf1;
    o.confirm_tolerance = 0.3 * deg;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out;
    tracker.add_frame(frame(0), WheelIncrement{}, &out0);
    const WheelIncrement straight{0.038, 0.038};
    for (int f = 1; f <= 2; ++f) {
      tracker.add_frame(frame(f), straight, &out);
      for (int k = 0; k < 6; ++k)
        EXPECT_EQ(out[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
      EXPECT_EQ(out[2].previous_verdict, LinkVerdict::kLinked);
    }
    tracker.add_frame(frame(3), straight, &out);
    for (int k : {0, 1, 3, 4, 5})
      EXPECT_EQ(out[static_cast<std::size_t>(k)].track_id, out0[k].track_id);
    SCOPED_TRACE(testing::Message() << "confirm_f1 " << c.cf1 << ", off " << c.off_deg
                                    << " deg, neighbour " << c.neighbour);
    if (c.linked) {
      EXPECT_EQ(out[2].track_id, out0[2].track_id);
      EXPECT_NEAR(out[2].distance, 0.48f, 0.01f);
    } else {
      EXPECT_TRUE(out[2].is_new());
      EXPECT_EQ(out[2].previous_verdict, LinkVerdict::kTest1);
      EXPECT_EQ(out[2].previous_candidate, 2);
    }
  }
}

// A fork: line A (track T) in frame 0; in frame 1 extraction finds its look-alike B instead
// (0.3 from A: linked to T); in frame 2 A again, 0.3 from A@0 but 0.42 from B, beyond F1 =
// 0.35, so it is not linked to B and looks back to A@0, forking T. heads_only refuses that
// link (T was observed since frame 0): a new track.
TEST(Tracker, HeadsOnlyRefusesAFork) {
  for (bool heads : {false, true}) {
    std::mt19937 rng(71);
    std::vector<Eigen::RowVectorXf> d;
    for (int k = 0; k < 6; ++k) d.push_back(random_descriptor(rng));
    const Eigen::RowVectorXf b = at_distance(d[0], random_descriptor(rng), 0.3);
    // A2 on a direction orthogonal to d[0] and to B's: |A2 - B| = sqrt(2) sin(a) = 0.42.
    const Eigen::RowVectorXf qb = (b - b.dot(d[0]) * d[0]).normalized();
    Eigen::RowVectorXf q = random_descriptor(rng);
    q -= q.dot(d[0]) * d[0];
    q -= q.dot(qb) * qb;
    const Eigen::RowVectorXf a2 = at_distance(d[0], q, 0.3);
    auto frame = [&](const Eigen::RowVectorXf& first) {
      FrameFeatures fr;
      fr.descriptors.resize(6, kPaperDescriptorSize);
      for (int k = 0; k < 6; ++k) {
        VerticalLine v;
        v.bearing = -2.5 + k;
        fr.lines.push_back(v);
        fr.descriptors.row(k) = k == 0 ? first : d[static_cast<std::size_t>(k)];
      }
      return fr;
    };
    TrackerOptions o = paper_tracker_options();
    o.match.f1 = 0.35;
    o.heads_only = heads;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out1, out2;
    tracker.add_frame(frame(d[0]), &out0);
    tracker.add_frame(frame(b), &out1);
    EXPECT_EQ(out1[0].track_id, out0[0].track_id);
    tracker.add_frame(frame(a2), &out2);
    EXPECT_GT((a2 - b).norm(), 0.35f);
    if (heads) {
      EXPECT_TRUE(out2[0].is_new());
      EXPECT_EQ(tracker.stats().rejected_fork, 1);
    } else {
      EXPECT_EQ(out2[0].track_id, out0[0].track_id);
      EXPECT_EQ(out2[0].frames_back, 2);
      EXPECT_EQ(tracker.stats().rejected_fork, 0);
    }
  }
}

}  // namespace
}  // namespace omnivert

namespace omnivert {
namespace {

TEST(TrackerOptions, PaperAndRecommended) {
  const TrackerOptions p = paper_tracker_options();
  EXPECT_EQ(p.look_back, 20);
  EXPECT_DOUBLE_EQ(p.match.f1, 1.05);
  EXPECT_DOUBLE_EQ(p.match.f2, 0.75);
  EXPECT_DOUBLE_EQ(p.match.f3, 0.8);
  EXPECT_FALSE(p.mutual);
  EXPECT_FALSE(p.gate.enabled);
  EXPECT_FALSE(p.same_polarity);
  EXPECT_EQ(p.continuity_tolerance, 0.0);
  std::string error;
  const TrackerOptions r = recommended_tracker_options(0.45);
  EXPECT_TRUE(r.IsValid(&error)) << error;
  EXPECT_TRUE(r.mutual);
  EXPECT_TRUE(r.same_polarity);
  EXPECT_NEAR(r.continuity_tolerance, 0.8 * kPi / 180.0, 1e-12);
  EXPECT_EQ(r.continuity_model, TrackerOptions::ContinuityModel::kTrack);
  EXPECT_DOUBLE_EQ(r.match.f1, 0.6);
  EXPECT_DOUBLE_EQ(r.look_back_f1, 0.5);
  EXPECT_FALSE(r.heads_only);
  EXPECT_EQ(p.continuity_model, TrackerOptions::ContinuityModel::kLink);
  EXPECT_EQ(p.look_back_f1, 0.0);
  EXPECT_FALSE(p.heads_only);
  EXPECT_TRUE(r.gate.enabled);
  EXPECT_DOUBLE_EQ(r.gate.wheel_base, 0.45);
  const TrackerOptions no_odometry = recommended_tracker_options(0.0);
  EXPECT_TRUE(no_odometry.IsValid(&error));
  EXPECT_FALSE(no_odometry.gate.enabled);
}

TEST(Tracker, BrokenFrameContractThrows) {
  Tracker t{TrackerOptions{}};
  std::vector<TrackAssignment> out;
  FrameFeatures f;
  f.lines.resize(3);
  f.descriptors = DescriptorMatrix::Zero(2, 192);
  EXPECT_THROW(t.add_frame(f, &out), std::invalid_argument);
  f.descriptors = DescriptorMatrix::Zero(3, 192);
  t.add_frame(f, &out);
  f.descriptors = DescriptorMatrix::Zero(3, 96);
  EXPECT_THROW(t.add_frame(f, &out), std::invalid_argument);
  Tracker gated{recommended_tracker_options(0.5)};
  f.descriptors = DescriptorMatrix::Zero(3, 192);
  EXPECT_THROW(gated.add_frame(f, &out), std::invalid_argument);  // no wheel increment
  gated.add_frame(f, WheelIncrement{}, &out);
}

TEST(Tracker, InvalidOptionsThrowInputError) {
  TrackerOptions o;
  o.look_back = 0;
  EXPECT_THROW(Tracker{o}, InputError);
  o = {};
  o.gate.enabled = true;  // no wheel base
  try {
    Tracker t(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("wheel base"), std::string::npos);
  }
}

}  // namespace
}  // namespace omnivert
