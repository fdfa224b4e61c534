// The tracker's odometry gate (bearing-change bounds, veto, gate-restricted candidates) and
// the same-polarity constraint.
#include "omnivert/match/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "tracker_sequence.hpp"

namespace omnivert {
namespace {

using namespace tracker_testing;

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

}  // namespace
}  // namespace omnivert
