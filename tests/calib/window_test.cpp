// The filter's start-up window (window.hpp): slipped tracks split in it, its starts at the
// camera yaw of the bearings' flow, tracks with only outliers or after a long gap, a window
// that cannot be solved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <Eigen/Dense>
#include <string>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "calib/updater.hpp"
#include "calib/window.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/flow_yaw.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {

// With the batch tests' models (test_support: the run's bearing noise).
namespace window_batch_cases {
namespace {

using test_support::nees;
using test_support::options_for;
using test_support::slip;
using test_support::truth_point;

// The filter's bootstrap window splits slipped tracks too. From pixels, on the office zigzag
// the window is most of the run (the heading never gets 1.5 rad from the start's: 252 of 269
// frames), so the window's solution is the filter's; here the window is made the whole run.
TEST(TrackSplitting, TheFiltersWindowSplitsSlippedTracks) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 7;
  const SyntheticRun clean = make_synthetic_run(so);
  const int n = static_cast<int>(clean.run.frames.size());
  SyntheticRun run = clean;
  std::map<int, int> slip_frame;
  int i = 0;
  for (const auto& [track, j] : clean.track_feature)
    if (i++ < 3) {
      slip_frame[track] = n / 3 + 7 * i;
      run = slip(run, track, slip_frame[track], 0.10);
    }
  CalibrationOptions o = options_for(so);
  o.association.crossing_guard = 0.0;   // the splitting alone (as above)
  o.filter.bootstrap_rotation = 100.0;  // never reached: the window ends with the run
  const FilterResult split = run_filter(run.run, o);
  o.association.split_chi2 = 0.0;
  const FilterResult whole = run_filter(run.run, o);
  const double nees_whole = test_support::nees(whole.extrinsics, whole.covariance, run.truth);
  const double nees_split = test_support::nees(split.extrinsics, split.covariance, run.truth);
  RecordProperty("nees_whole", std::to_string(nees_whole));
  RecordProperty("nees_split", std::to_string(nees_split));
  EXPECT_TRUE(whole.splits.empty());
  EXPECT_GT(nees_whole, 16.3);  // chi-square(3) 99.9% quantile: the slips bias the estimate
  EXPECT_LT(nees_split, 7.81);  // 95%: consistent again
  ASSERT_EQ(split.splits.size(), 3u);
  for (const auto& [track, frame] : split.splits) {
    ASSERT_TRUE(slip_frame.count(track)) << "track " << track << " split at " << frame;
    EXPECT_NEAR(frame, slip_frame.at(track), 8) << "track " << track;
  }
  // Each slipped track's latest part is what the filter ends with.
  for (const auto& [track, frame] : split.splits) EXPECT_GE(split.tracks.at(track).frame, frame);
}

// (phi + pi, -rho, psi - pi) is the same camera pose as (phi, rho, psi): a refinement started
// on that mirror stays there (every residual is the same), and must report rho >= 0.
// calib::camera_yaw_from_flow: the camera yaw phi + psi from the direction the bearings flow
// from while the robot drives (eq. 30), whatever the mounting; NaN without translation.
TEST(WindowStarts, CameraYawFromTheBearingsFlow) {
  for (const Trajectory trajectory : {Trajectory::kPaper, Trajectory::kZigzag}) {
    for (const double yaw : {-2.8, -1.876, -0.6, 0.0, 1.4, 3.0}) {
      SyntheticRunOptions o;
      o.trajectory = trajectory;
      o.bearing_sigma = 0.03 * kPi / 180.0;
      o.num_features = 15;
      o.truth = {0.7, 0.2, wrap_angle(yaw - 0.7)};
      o.seed = 3;
      const SyntheticRun s = make_synthetic_run(o);
      const double flow = camera_yaw_from_flow(s.run, o.wheel_base);
      ASSERT_TRUE(std::isfinite(flow)) << "yaw " << yaw;
      // The bound: the window's starts are taken at the flow's yaw when it is more than 0.35
      // rad from the prior's; off by 0.2 rad they converge (docs/theory/window.md#starts).
      EXPECT_LT(std::abs(wrap_angle(flow - yaw)), 0.2) << "yaw " << yaw << " flow " << flow;
    }
  }
  // Turns in place only (the paper run's turn, its wheels' travel exactly opposite): the
  // camera moves on a circle of radius rho but the robot does not drive, so the flow tells
  // nothing.
  SyntheticRunOptions o;
  o.bearing_sigma = 0.03 * kPi / 180.0;
  const SyntheticRun s = make_synthetic_run(o);
  CalibrationRun turn;
  for (const FrameInput& f : s.run.frames)
    if (std::abs(f.d_right - f.d_left) > std::abs(f.d_right + f.d_left)) {
      turn.frames.push_back(f);
      turn.frames.back().d_left = -f.d_right;
    }
  ASSERT_GT(turn.frames.size(), 40u);
  EXPECT_TRUE(std::isnan(camera_yaw_from_flow(turn, o.wheel_base)));
}

}  // namespace
}  // namespace window_batch_cases

// With the filter tests' models (bearing sigma 0.3 degree).
namespace window_filter_cases {
namespace {

CalibrationOptions options_for(const SyntheticRunOptions& so) {
  return test_support::filter_case_options(so);
}
using test_support::error;

// A track whose every bearing is an outlier in the bootstrap window (two rays that diverge:
// no point fits either to the gate) loses all its bearings there; its feature must leave the
// window's problem, whose information is singular otherwise (the inverse-depth prior alone
// leaves the point free across the ray: a zero pivot, whose rounded sign would decide whether
// the window is refused; refused, the undelayed fallback can end far off).
TEST(CalibrationFilter, BootstrapWindowDropsATrackWithOnlyOutliers) {
  SyntheticRunOptions so;
  so.seed = 3;
  const SyntheticRun run = make_synthetic_run(so);
  CalibrationRun window = run.run;  // the whole run: a straight and the turn
  ASSERT_GT(window.frames.size(), 50u);
  // Frames 10 and 11 are on the first straight (the robot drives along its x-axis): from
  // frame 10 the ray points 5 degrees behind the left, from frame 11 5 degrees ahead of it.
  const double yaw = run.truth.phi + run.truth.psi;
  for (int j = 0; j < 8; ++j) {
    window.frames[10 + 5 * j].observations.push_back({900 + j, deg2rad(95.0) - yaw});
    window.frames[11 + 5 * j].observations.push_back({900 + j, deg2rad(85.0) - yaw});
  }
  const CalibrationOptions o = options_for(so);
  FilterState state(o.prior.mean, o.prior.sigma, ExtrinsicsParam::kCameraPose);
  std::string why;
  BootstrapDetails details;
  ASSERT_TRUE(bootstrap_filter_state(window, o, &state, &why, &details)) << why;
  for (const FeatureSlot& s : state.slots()) EXPECT_LT(s.track_id, 900);
  for (const auto& [id, t] : details.tracks) EXPECT_LT(id, 900) << "a feature without bearings";
  EXPECT_EQ(details.tracks.size(), static_cast<std::size_t>(so.num_features));
  EXPECT_EQ(state.num_features(), so.num_features);
  const Eigen::Vector3d e = error(state.extrinsics(), run.truth);
  const Eigen::Matrix3d C = state.extrinsics_covariance();
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(e(i)), 4.0 * std::sqrt(C(i, i))) << i;
}

// A track not seen for more than max_missed_frames has ended, in the window as in the filter:
// a bearing with its id after such a gap is another track (here one with a single bearing,
// which the window cannot use), not a long-baseline observation of the first. (From pixels,
// such a lone bearing where two lines crossed was 0.11 degree off and made the window's phi
// three times too certain.)
TEST(CalibrationFilter, BootstrapWindowEndsATrackAfterALongGap) {
  SyntheticRunOptions so;
  so.seed = 3;
  so.bearing_sigma = deg2rad(0.05);
  const SyntheticRun run = make_synthetic_run(so);
  CalibrationOptions o = options_for(so);
  o.noise.bearing_sigma = so.bearing_sigma;
  const int gap_frame =
      o.association.max_missed_frames + 21;  // 11 frames after the track's last + margin
  // A track seen in frames 0-10 and at gap_frame.
  int id = -1;
  for (const BearingObservation& b : run.run.frames[0].observations)
    for (const BearingObservation& c : run.run.frames[gap_frame].observations)
      if (b.track_id == c.track_id && id < 0) id = b.track_id;
  ASSERT_GE(id, 0);
  CalibrationRun clean = run.run;
  for (int k = 11; k < static_cast<int>(clean.frames.size()); ++k) {
    auto& obs = clean.frames[k].observations;
    obs.erase(
        std::remove_if(
            obs.begin(), obs.end(), [id](const BearingObservation& b) { return b.track_id == id; }),
        obs.end());
  }
  CalibrationRun lone = clean;
  for (const BearingObservation& c : run.run.frames[gap_frame].observations)
    if (c.track_id == id)
      lone.frames[gap_frame].observations.push_back({id, c.beta + deg2rad(0.3)});
  std::string why;
  FilterState a(o.prior.mean, o.prior.sigma, ExtrinsicsParam::kCameraPose), b = a;
  ASSERT_TRUE(bootstrap_filter_state(clean, o, &a, &why)) << why;
  ASSERT_TRUE(bootstrap_filter_state(lone, o, &b, &why)) << why;
  EXPECT_LT((a.extrinsics().vec() - b.extrinsics().vec()).norm(), 1e-9);
  EXPECT_LT((a.extrinsics_covariance() - b.extrinsics_covariance()).norm(),
            1e-9 * a.extrinsics_covariance().norm());
}

// A window that cannot be solved (here: no track seen twice in it) is reported, with the
// frames it held, and the user is told (calibrate's result_warnings).
TEST(CalibrationFilter, AnUnsolvableWindowIsReported) {
  SyntheticRunOptions so;
  so.seed = 4;
  SyntheticRun run = make_synthetic_run(so);
  // Every bearing of the first 100 frames (the window ends at the turn, before) under its own
  // track id: nothing to triangulate.
  int id = 100000;
  for (int k = 0; k < 100; ++k)
    for (BearingObservation& o : run.run.frames[k].observations) o.track_id = id++;
  CalibrationOptions o = options_for(so);
  o.association.max_missed_frames = 0;  // tracks not seen leave at once (the state stays small)
  const FilterResult fr = run_filter(run.run, o);
  EXPECT_GT(fr.window_frames, 0);
  EXPECT_NE(fr.window_failure.find("no track with two bearings"), std::string::npos)
      << fr.window_failure;
  CalibrationResult cr;
  cr.filter = fr;
  bool told = false;
  for (const std::string& w : result_warnings(cr))
    told |= w.find("start-up window") != std::string::npos;
  EXPECT_TRUE(told);
  // A clean run: solved, nothing said.
  const FilterResult clean = run_filter(make_synthetic_run(so).run, o);
  EXPECT_GT(clean.window_frames, 0);
  EXPECT_TRUE(clean.window_failure.empty()) << clean.window_failure;
}

}  // namespace
}  // namespace window_filter_cases
}  // namespace omnivert::calib
