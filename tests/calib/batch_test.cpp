// The batch refinement's track splitting (BatchOptions::split_chi2): a track that slipped
// onto a neighbouring line (the office's door leaf 6 cm inside its frame, docs/calib.md) is
// split in two, which removes the bias it puts on the extrinsics; clean tracks are left whole.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <Eigen/Dense>

#include "omnivert/calib/batch_point.hpp"
#include "omnivert/calib/diagnostics.hpp"
#include "omnivert/calib/flow_yaw.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/calib/track_ids.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/report.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/synthetic_run.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::options_for;
using test_support::truth_point;

double nees(const RefinementResult& r, const Extrinsics& truth) {
  return test_support::nees(r.extrinsics, r.covariance, truth);
}

// From frame `from` on, the track of feature `f` follows a second line `behind` metres further
// along the camera's ray of frame `from` (same noise): at the slip the two bearings coincide,
// afterwards they drift apart as the robot moves, as a door leaf does behind its frame.
SyntheticRun slip(SyntheticRun run, int track, int from, double behind) {
  const Eigen::Vector2d f = run.features[run.track_feature.at(track)];
  const Eigen::Vector3d& p = run.true_poses[from];
  const double a = p(2) + run.truth.phi;
  const Eigen::Vector2d c(p(0) + run.truth.rho * std::cos(a), p(1) + run.truth.rho * std::sin(a));
  const Eigen::Vector2d g = f + behind * (f - c).normalized();
  for (std::size_t k = from; k < run.run.frames.size(); ++k)
    for (BearingObservation& o : run.run.frames[k].observations)
      if (o.track_id == track)
        o.beta += bearing_from_geometry(run.true_poses[k], g, run.truth) -
                  bearing_from_geometry(run.true_poses[k], f, run.truth);
  return run;
}

TEST(TrackSplitting, SlippedTracksAreSplitAndTheirBiasRemoved) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);  // the extractor's noise
  so.seed = 7;
  const SyntheticRun clean = make_synthetic_run(so);
  const int n = static_cast<int>(clean.run.frames.size());
  SyntheticRun run = clean;
  int i = 0;
  for (const auto& [track, j] : clean.track_feature)
    if (i++ < 3) run = slip(run, track, n / 3 + 7 * i, 0.10);
  // The splitting alone: the crossing guard leaves out other bearings of this run and moves
  // its NEES by chance (the clean run's: 5.3 without the guard, 6.8 with it). Over seeds
  // 7-46 it changes nothing on average (docs/calib.md, "Lines that cross").
  Options o = options_for(so);
  o.crossing_guard = 0.0;
  BatchOptions off;
  off.split_chi2 = 0.0;
  const RefinementResult whole = refine_batch(run.run, o, truth_point(run), off);
  const RefinementResult split = refine_batch(run.run, o, truth_point(run));
  ASSERT_TRUE(whole.covariance_ok);
  ASSERT_TRUE(split.covariance_ok);
  const double nees_whole = nees(whole, run.truth), nees_split = nees(split, run.truth);
  EXPECT_EQ(whole.num_splits, 0);
  EXPECT_EQ(split.num_splits, 3);
  EXPECT_EQ(split.num_features, whole.num_features + split.num_splits);
  // The run the solution refers to: the split parts under new ids, every feature of the
  // solution observed in it (what calibrate() hands to the observability analysis).
  std::map<int, int> seen;
  for (const FrameInput& f : split.solved_run.frames)
    for (const BearingObservation& ob : f.observations) ++seen[ob.track_id];
  EXPECT_EQ(seen.size(), clean.track_feature.size() + 3);
  for (const auto& [id, p] : split.solution.features) EXPECT_GT(seen[id], 0) << "feature " << id;
  EXPECT_GT(nees_whole, 16.3);  // chi-square(3) 99.9% quantile: the slips bias the estimate
  EXPECT_LT(nees_split, 7.81);  // 95%: consistent again
  RecordProperty("nees_whole", std::to_string(nees_whole));
  RecordProperty("nees_split", std::to_string(nees_split));
  // Each slipped track is split within a few frames of its slip (near the slip the two
  // lines' bearings coincide, so the exact frame is not determined), and only those.
  std::map<int, int> slip_frame;
  i = 0;
  for (const auto& [track, j] : clean.track_feature)
    if (i++ < 3) slip_frame[track] = n / 3 + 7 * i;
  for (const auto& [track, frame] : split.splits) {
    ASSERT_TRUE(slip_frame.count(track)) << "track " << track << " split at " << frame;
    EXPECT_NEAR(frame, slip_frame.at(track), 8) << "track " << track;
  }
}

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
  Options o = options_for(so);
  o.crossing_guard = 0.0;        // the splitting alone (as above)
  o.bootstrap_rotation = 100.0;  // never reached: the window ends with the run
  const FilterResult split = run_filter(run.run, o);
  o.split_chi2 = 0.0;
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

// split_tracks cuts each track at its split frames, the parts under new ids: the same parts
// as the refinement's own split run.
TEST(TrackSplitting, SplitTracksRebuildsTheRefinementsParts) {
  CalibrationRun run;
  run.frames.resize(10);
  for (int k = 0; k < 10; ++k) {
    run.frames[k].observations.push_back({3, 0.1 * k});
    if (k >= 2) run.frames[k].observations.push_back({8, -0.1 * k});
  }
  std::map<int, int> origin;
  const CalibrationRun out = split_tracks(run, {{3, 6}, {3, 4}, {8, 9}}, &origin);
  // Track 3: frames 0-3 keep id 3, 4-5 and 6-9 get new ids; track 8: 2-8 keep 8, 9 new.
  std::vector<int> id3, id8;
  for (int k = 0; k < 10; ++k) {
    id3.push_back(out.frames[k].observations[0].track_id);
    EXPECT_DOUBLE_EQ(out.frames[k].observations[0].beta, 0.1 * k);
    if (k >= 2) id8.push_back(out.frames[k].observations[1].track_id);
  }
  EXPECT_EQ(id3[0], 3);
  EXPECT_EQ(id3[3], 3);
  EXPECT_EQ(id3[4], id3[5]);
  EXPECT_EQ(id3[6], id3[9]);
  EXPECT_NE(id3[4], id3[6]);
  EXPECT_GT(id3[4], 8);
  EXPECT_GT(id3[6], 8);
  EXPECT_EQ(id8[0], 8);
  EXPECT_EQ(id8[6], 8);
  EXPECT_GT(id8[7], 8);
  EXPECT_NE(id8[7], id3[4]);
  EXPECT_NE(id8[7], id3[6]);
  EXPECT_EQ(origin.size(), 3u);
  EXPECT_EQ(origin.at(id3[4]), 3);
  EXPECT_EQ(origin.at(id3[6]), 3);
  EXPECT_EQ(origin.at(id8[7]), 8);
  EXPECT_EQ(split_tracks(run, {}).frames[5].observations[1].track_id, 8);
}

// Clean runs (no slip): splitting finds nothing to split, and the estimate is unchanged.
TEST(TrackSplitting, CleanTracksAreLeftWhole) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  int splits = 0;
  for (int s = 1; s <= 10; ++s) {
    so.seed = 200 + s;
    so.trajectory = s % 2 ? Trajectory::kPaper : Trajectory::kZigzag;
    const SyntheticRun run = make_synthetic_run(so);
    const RefinementResult r = refine_batch(run.run, options_for(so), truth_point(run));
    splits += r.num_splits;
    if (r.num_splits == 0) {
      BatchOptions off;
      off.split_chi2 = 0.0;
      const RefinementResult w = refine_batch(run.run, options_for(so), truth_point(run), off);
      EXPECT_DOUBLE_EQ(w.extrinsics.phi, r.extrinsics.phi);
      EXPECT_DOUBLE_EQ(w.extrinsics.rho, r.extrinsics.rho);
    }
  }
  EXPECT_LE(splits, 1) << "false splits in 10 clean runs";
}

// The extractor sees one line where two lines are closer than its resolution: one detection,
// pulled between them, given to one of the two tracks (the other track misses the frame);
// a little further apart, two detections, each pulled towards the other. Here: where two
// features' true bearings are within `merged`, the lower track gets the mean of the two
// bearings and the other track loses its bearing; within `pulled`, each bearing moves by
// `pull` of the separation towards the other.
SyntheticRun merge_crossings(SyntheticRun run, double merged, double pulled, double pull) {
  for (std::size_t k = 0; k < run.run.frames.size(); ++k) {
    auto& obs = run.run.frames[k].observations;
    std::vector<double> truth(obs.size());
    for (std::size_t i = 0; i < obs.size(); ++i)
      truth[i] = bearing_from_geometry(run.true_poses[k],
                                       run.features[run.track_feature.at(obs[i].track_id)], run.truth);
    std::vector<char> gone(obs.size(), 0);
    std::vector<double> shift(obs.size(), 0.0);
    for (std::size_t i = 0; i < obs.size(); ++i)
      for (std::size_t j = i + 1; j < obs.size(); ++j) {
        const double d = wrap_angle(truth[j] - truth[i]);
        if (gone[i] || gone[j] || std::abs(d) >= pulled) continue;
        if (std::abs(d) < merged) {
          shift[i] += 0.5 * wrap_angle(obs[j].beta - obs[i].beta);
          gone[j] = 1;
        } else {
          shift[i] += pull * d;
          shift[j] -= pull * d;
        }
      }
    for (std::size_t i = 0; i < obs.size(); ++i) obs[i].beta += shift[i];
    std::vector<BearingObservation> kept;
    for (std::size_t i = 0; i < obs.size(); ++i)
      if (!gone[i]) kept.push_back(obs[i]);
    obs = std::move(kept);
  }
  return run;
}

// The crossing tests' runs: 30 features at the extractor's noise, seed 300 + s, clean and
// with merged detections (within 0.4 degree) and pulled ones (a fifth of the separation,
// within the guard).
SyntheticRunOptions crossing_options(int s) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.num_features = 30;
  so.seed = 300 + s;
  return so;
}
SyntheticRun with_crossings(const SyntheticRun& clean) {
  return merge_crossings(clean, deg2rad(0.4), Options{}.crossing_guard, 0.2);
}

// The crossing guard (Options::crossing_guard) leaves out exactly the bearings where another
// feature is within the guard, and with it merged detections no longer move the estimate:
// the run with merged detections gives the clean run's estimate; without the guard it does
// not.
TEST(CrossingGuard, MergedDetectionsAreLeftOutAndDoNotMoveTheEstimate) {
  const int runs = 10;
  double moved_on = 0.0, moved_off = 0.0;  // mean squared Mahalanobis shift from the clean run
  int guarded = 0, bearings = 0;
  auto shift = [](const RefinementResult& a, const RefinementResult& clean) {
    return test_support::nees(a.extrinsics, clean.covariance, clean.extrinsics);
  };
  for (int s = 1; s <= runs; ++s) {
    const SyntheticRunOptions so = crossing_options(s);
    const SyntheticRun clean = make_synthetic_run(so);
    const SyntheticRun run = with_crossings(clean);
    Options o = options_for(so);
    const RefinementResult on = refine_batch(run.run, o, truth_point(run));
    const RefinementResult on_clean = refine_batch(clean.run, o, truth_point(clean));
    o.crossing_guard = 0.0;
    const RefinementResult off = refine_batch(run.run, o, truth_point(run));
    const RefinementResult off_clean = refine_batch(clean.run, o, truth_point(clean));
    ASSERT_TRUE(on.covariance_ok && off.covariance_ok && on_clean.covariance_ok &&
                off_clean.covariance_ok);
    moved_on += shift(on, on_clean) / runs;
    moved_off += shift(off, off_clean) / runs;
    EXPECT_TRUE(off.guarded.empty());
    guarded += static_cast<int>(on.guarded.size());
    bearings += off.num_bearings;
    // Known geometry, known answer: a bearing is left out where another feature's true
    // bearing is within the guard (0.75 degree; to 0.2 degree: the guard judges at the estimate, whose
    // features are a few millimetres off; measured up to 0.15), that feature's track seen
    // within max_missed_frames.
    std::map<int, std::pair<int, int>> span;
    for (std::size_t k = 0; k < run.run.frames.size(); ++k)
      for (const BearingObservation& ob : run.run.frames[k].observations) {
        auto [it, fresh] = span.emplace(ob.track_id, std::make_pair(int(k), int(k)));
        it->second.second = static_cast<int>(k);
      }
    const double guard = Options{}.crossing_guard, tol = deg2rad(0.2);
    const std::set<std::pair<int, int>> left_out(on.guarded.begin(), on.guarded.end());
    int wrong = 0;
    for (std::size_t k = 0; k < run.run.frames.size(); ++k)
      for (const BearingObservation& ob : run.run.frames[k].observations) {
        const int kk = static_cast<int>(k), m = o.max_missed_frames;
        const double mine = bearing_from_geometry(
            run.true_poses[k], run.features[run.track_feature.at(ob.track_id)], run.truth);
        double nearest = kPi;
        for (const auto& [id, j] : run.track_feature)
          if (id != ob.track_id && span.count(id) && span[id].first - m <= kk &&
              kk <= span[id].second + m)
            nearest = std::min(nearest, std::abs(wrap_angle(bearing_from_geometry(
                                            run.true_poses[k], run.features[j], run.truth) - mine)));
        const bool out = left_out.count({ob.track_id, kk}) > 0;
        if ((nearest < guard - tol && !out) || (nearest > guard + tol && out)) ++wrong;
      }
    EXPECT_EQ(wrong, 0) << "seed " << so.seed;
  }
  // Guarded, the merged run's estimate is the clean run's to a small fraction of its sigma
  // (measured 0.023); unguarded, it moves (measured 0.213).
  EXPECT_LT(moved_on, 0.05);
  EXPECT_GT(moved_off, 0.15);
  EXPECT_GT(moved_off, 4.0 * moved_on);
  RecordProperty("moved_on", std::to_string(moved_on));
  RecordProperty("moved_off", std::to_string(moved_off));
  std::printf("guarded %d of %d bearings; shift from the clean run: guard %.3f, none %.3f\n",
              guarded, bearings, moved_on, moved_off);
}

// The filter's guard, in its window and in the EKF after it: the same comparison.
TEST(CrossingGuard, TheFilterLeavesOutMergedDetections) {
  const int runs = 10;
  double moved_on = 0.0, moved_off = 0.0;
  int after_window = 0;
  auto shift = [](const FilterResult& a, const FilterResult& clean) {
    return test_support::nees(a.extrinsics, clean.covariance, clean.extrinsics);
  };
  for (int s = 1; s <= runs; ++s) {
    const SyntheticRunOptions so = crossing_options(s);
    const SyntheticRun clean = make_synthetic_run(so);
    const SyntheticRun run = with_crossings(clean);
    Options o = options_for(so);
    const FilterResult on = run_filter(run.run, o), on_clean = run_filter(clean.run, o);
    o.crossing_guard = 0.0;
    const FilterResult off = run_filter(run.run, o), off_clean = run_filter(clean.run, o);
    ASSERT_TRUE(on.window_failure.empty() && off.window_failure.empty());
    moved_on += shift(on, on_clean) / runs;
    moved_off += shift(off, off_clean) / runs;
    EXPECT_TRUE(off.guarded.empty());
    int in_history = 0;
    for (const FrameEstimate& h : on.history) in_history += h.num_guarded;
    for (const auto& [id, k] : on.guarded) after_window += k >= on.window_frames ? 1 : 0;
    // Every guarded bearing is counted in its frame's record (states.csv) as well.
    EXPECT_EQ(in_history, static_cast<int>(on.guarded.size()));
  }
  EXPECT_GT(after_window, 0);  // the EKF's guard acted, not only the window's
  // Measured: 0.22 with the guard, 1.05 without. (Not all of the merged detections are left
  // out: the filter knows a line once its track has started; guard_before_starts carries a
  // new track's separation back only as a straight line over its first frames.)
  EXPECT_LT(moved_on, 0.3);
  EXPECT_GT(moved_off, 0.6);
  EXPECT_GT(moved_off, 3.0 * moved_on);
  RecordProperty("moved_on", std::to_string(moved_on));
  RecordProperty("moved_off", std::to_string(moved_off));
  std::printf("filter: shift from the clean run: guard %.3f, none %.3f; %d left out after the "
              "window\n", moved_on, moved_off, after_window);
}

// The guard ahead of a track's start (guard_before_starts), on known separations: line a is
// tracked over frames 0-30; line b's track starts at frame 20, 0.3 degree from a, and parts at
// 0.1 degree a frame; line c, 10 degrees away, starts at frame 25. Carried back, b is within
// the guard (0.75 degree) of a over frames 10-19 (-0.7 degree at 10, -0.8 at 9): exactly those
// bearings of a are returned, none of c's or b's, and none near c's start.
TEST(CrossingGuard, BeforeATrackStartsBesideAnother) {
  CalibrationRun run;
  run.frames.resize(31);
  const double a0 = 0.4, rate = deg2rad(0.1);
  for (int k = 0; k <= 30; ++k) {
    auto& obs = run.frames[static_cast<std::size_t>(k)].observations;
    const double a = a0 + 0.01 * k;  // a turns as the robot drives
    obs.push_back({1, a});
    if (k >= 20) obs.push_back({2, a + deg2rad(0.3) + rate * (k - 20)});
    if (k >= 25) obs.push_back({3, a + deg2rad(10.0)});
  }
  Options o;
  ASSERT_NEAR(o.crossing_guard, deg2rad(0.75), 1e-12);
  std::map<std::pair<int, int>, int> expected;  // (track, frame) -> where the other starts
  for (int k = 10; k <= 19; ++k) expected[{1, k}] = 20;
  EXPECT_EQ(guard_before_starts(run, o), expected);
  o.crossing_guard = 0.0;  // the guard off: nothing
  EXPECT_TRUE(guard_before_starts(run, o).empty());
}

// A tracker that loses a line and finds it again gives it a new id: the pieces of one line
// are not lines that cross, and must not guard each other (reject_crossings, one_line). Tracks
// broken every ~10 frames (break probability 0.1, about 110 tracks of 10 lines): before, the
// guard left out most bearings (the refinement kept 4-15 tracks), the window barely left the
// prior and no seed was determined (errors up to 0.8 rad and 350 mm, 100-350 bounds).
TEST(CrossingGuard, PiecesOfOneLineDoNotGuardEachOther) {
  for (int s = 1; s <= 3; ++s) {
    SyntheticRunOptions so;
    so.seed = static_cast<std::uint64_t>(s);
    so.bearing_sigma = deg2rad(0.025);
    so.break_probability = 0.1;
    const SyntheticRun run = make_synthetic_run(so);
    int bearings = 0;
    for (const FrameInput& f : run.run.frames) bearings += static_cast<int>(f.observations.size());
    const CalibrationResult r = calibrate(run.run, options_for(so), {.refine = true});
    ASSERT_TRUE(r.observability.all_determined()) << "seed " << s << ": " << r.observability.message;
    // Measured (seeds 1-8): at most 0.017 rad and 5.2 mm off, against bounds of 4-13 mrad
    // and 1.4-5.3 mm at the truth.
    EXPECT_LT(test_support::nees(r.refinement.extrinsics, r.refinement.covariance, run.truth), 16.3)
        << "seed " << s;
    EXPECT_LT(test_support::nees(r.filter.extrinsics, r.filter.covariance, run.truth), 16.3)
        << "seed " << s;
    EXPECT_LT(r.refinement.guarded.size(), 0.15 * bearings) << "seed " << s;
    // The pieces are in the problem, as features of their own or joined to their line
    // (PiecesOfOneLine below): 10 lines, more than 50 pieces.
    EXPECT_GT(r.refinement.num_features + static_cast<int>(r.refinement.merges.size()), 50)
        << "seed " << s;
  }
}

// A tracker that loses lines and finds them again under new ids (a new id with probability
// 0.1 per frame: pieces of ~10 frames). The refinement joins the pieces of each line
// (BatchOptions::merge_pieces) and so reaches nearly the precision of the whole tracks.
// Seeds 69 and 90: with the Wald test alone, 2 and 4 joins were of two lines (a three-bearing
// piece has no depth and passed it at 0.00), and the refinement ended with NEES 46 and 1547.
// Chains of joins are followed to the line's first piece; of two joins of one piece the last
// counts; a join of a piece to itself and one that closes a loop are left out, so every chain
// ends (the window reports joins by the tracker's ids, and a corridor zigzag run hung on
// (T, T)).
TEST(PiecesOfOneLine, JoinChainsEndAtTheFirstPiece) {
  // Taken from the last: 8 -> 7, 2 -> 5, 1 -> 3, (3, 3) left out, 3 -> 2; (1, 2) is a second
  // join of 2, left out. The chains: 1 -> 3 -> 2 -> 5.
  const std::map<int, int> r = join_roots({{1, 2}, {2, 3}, {3, 3}, {3, 1}, {5, 2}, {7, 8}});
  const std::map<int, int> expected = {{1, 5}, {2, 5}, {3, 5}, {8, 7}};
  EXPECT_EQ(r, expected);
  EXPECT_TRUE(join_roots({{4, 4}}).empty());
  // A loop: the last pair is kept, the one that would close the loop left out.
  const std::map<int, int> two = join_roots({{4, 6}, {6, 4}});
  EXPECT_EQ(two, (std::map<int, int>{{4, 6}}));
  // Without loops or repeats, plain chains.
  const std::map<int, int> chain = join_roots({{1, 2}, {2, 3}, {3, 4}});
  EXPECT_EQ(chain, (std::map<int, int>{{2, 1}, {3, 1}, {4, 1}}));
}

TEST(PiecesOfOneLine, AreJoinedOnlyWithTheirOwnLine) {
  for (const int s : {1, 7, 69, 90}) {
    SyntheticRunOptions so;
    so.seed = static_cast<std::uint64_t>(s);
    so.bearing_sigma = deg2rad(0.03);
    so.break_probability = 0.1;
    const SyntheticRun run = make_synthetic_run(so);
    const Options o = options_for(so);
    CalibrateOptions on{.refine = true}, off{.refine = true};
    off.batch.merge_pieces = false;
    const RefinementResult r = calibrate(run.run, o, on).refinement;
    const RefinementResult apart = calibrate(run.run, o, off).refinement;
    // The same run with each line under one id.
    CalibrationRun whole_run = run.run;
    for (FrameInput& f : whole_run.frames)
      for (BearingObservation& b : f.observations) b.track_id = run.track_feature.at(b.track_id);
    const RefinementResult whole = calibrate(whole_run, o, off).refinement;
    ASSERT_TRUE(r.covariance_ok && apart.covariance_ok && whole.covariance_ok) << "seed " << s;
    int wrong = 0;
    for (const auto& [a, c] : r.merges) wrong += run.track_feature.at(a) != run.track_feature.at(c);
    EXPECT_EQ(wrong, 0) << "seed " << s << ": joins of two lines, of " << r.merges.size();
    EXPECT_GT(r.merges.size(), 30u) << "seed " << s;
    const double sr = std::sqrt(r.covariance(1, 1)), sa = std::sqrt(apart.covariance(1, 1)),
                 sw = std::sqrt(whole.covariance(1, 1));
    std::printf("seed %d: %zu joins; sigma rho %.2f mm joined, %.2f apart, %.2f whole; NEES %.2f %.2f %.2f\n",
                s, r.merges.size(), 1e3 * sr, 1e3 * sa, 1e3 * sw, nees(r, run.truth),
                nees(apart, run.truth), nees(whole, run.truth));
    // Seed 90 joins 44 pieces where the others join 64-87: its refinement from the filter's
    // start holds some pieces of one line apart (held poses: one_point_statistic above the
    // gate), and reaches 2.4 mm against 0.46 for the whole tracks and 5.4 apart.
    if (s != 90) EXPECT_LT(sr, 1.3 * sw) << "seed " << s;
    EXPECT_LT(sr, 0.6 * sa) << "seed " << s;
    EXPECT_LT(nees(r, run.truth), 16.3) << "seed " << s;  // chi-square(3), 0.999
    // The bearings the solution used or left out are those of the run under the ids it
    // solved (RefinementResult::solved_run).
    int n = 0, m = 0;
    for (const FrameInput& f : run.run.frames) n += static_cast<int>(f.observations.size());
    for (const FrameInput& f : r.solved_run.frames) m += static_cast<int>(f.observations.size());
    EXPECT_EQ(m, n);
    EXPECT_EQ(r.num_bearings + static_cast<int>(r.guarded.size() + r.rejected.size()), n);
  }
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
      // rad from the prior's; off by 0.2 rad they converge (docs/calib.md, "Window starts").
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

TEST(Refinement, MirroredExtrinsicsAreReportedWithPositiveRho) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 3;
  const SyntheticRun run = make_synthetic_run(so);
  BatchPoint start = truth_point(run);
  start.extrinsics = {run.truth.phi + kPi, -run.truth.rho, run.truth.psi - kPi};
  const RefinementResult r = refine_batch(run.run, options_for(so), start);
  ASSERT_TRUE(r.covariance_ok);
  EXPECT_GT(r.extrinsics.rho, 0.0);
  EXPECT_NEAR(r.extrinsics.rho, run.truth.rho, 0.01);
  EXPECT_NEAR(wrap_angle(r.extrinsics.phi - run.truth.phi), 0.0, deg2rad(2.0));
  EXPECT_NEAR(wrap_angle(r.extrinsics.psi - run.truth.psi), 0.0, deg2rad(2.0));
  EXPECT_LT(nees(r, run.truth), 16.3);
  const RefinementResult direct = refine_batch(run.run, options_for(so), truth_point(run));
  EXPECT_NEAR(r.extrinsics.rho, direct.extrinsics.rho, 1e-6);
  EXPECT_NEAR(std::sqrt(r.covariance(1, 1)), std::sqrt(direct.covariance(1, 1)), 1e-6);
}

}  // namespace
}  // namespace omnivert::calib

#include "omnivert/calib/calibrate.hpp"

namespace omnivert::calib {
namespace {

// result_warnings: a filter that refused many bearings, and a refinement outside the filter's
// 99.9% ellipsoid, are told; a consistent pair is not.
TEST(ResultWarnings, DivergenceAndDisagreementAreTold) {
  CalibrationResult r;
  r.filter.extrinsics = {-0.34, 0.23, 0.33};
  r.filter.covariance = Eigen::Vector3d(1e-4, 1e-6, 1e-4).asDiagonal();  // sigmas 0.57 deg, 1 mm
  for (int k = 0; k < 10; ++k) {
    FrameEstimate h;
    h.num_updates = 8;
    h.num_rejected = 2;  // 20%: not more than 20%
    r.filter.history.push_back(h);
  }
  EXPECT_TRUE(result_warnings(r).empty());
  r.filter.history[0].num_rejected = 3;
  std::vector<std::string> w = result_warnings(r);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("refused 21 of 101 bearings"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("--refine"), std::string::npos);
  r.filter.history[0].num_rejected = 2;
  r.refined = true;
  r.refinement.covariance_ok = true;
  r.refinement.extrinsics = {-0.34 + 0.02, 0.23 + 0.002, 0.33 - 0.02};  // (2 + 2 + 4) = 8
  EXPECT_TRUE(result_warnings(r).empty());
  r.refinement.extrinsics = {-0.34 + 0.03, 0.23 + 0.003, 0.33 - 0.03};  // 9 + 9 + 9 = 27
  w = result_warnings(r);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("disagree (squared Mahalanobis distance 27.0"), std::string::npos) << w[0];
  // Angles wrap: the same pair two turns apart is no disagreement.
  r.refinement.extrinsics = {-0.34 + 4 * kPi, 0.23, 0.33 - 2 * kPi};
  EXPECT_TRUE(result_warnings(r).empty());
}

}  // namespace
}  // namespace omnivert::calib

namespace omnivert::calib {
namespace {

using test_support::options_for;
using test_support::truth_point;

// The data's own check of the bearing noise (RefinementResult::noise, the cluster-robust
// covariance with each track as a cluster). Monte Carlo over synthetic paper runs refined
// from the truth; returns the mean scale and the mean NEES with the model's and with the
// checked covariance.
struct NoiseCheckStats {
  double scale = 0, nees_model = 0, nees_checked = 0;
  int runs = 0;
};
NoiseCheckStats noise_check_monte_carlo(double true_sigma_deg, double correlation, int runs,
                                        double gate_probability = 0.999,
                                        const BatchOptions& batch = {}) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(true_sigma_deg);
  so.bearing_correlation = correlation;
  Options o = options_for(so);
  o.bearing_sigma = deg2rad(0.05);  // what the model assumes
  o.gate_probability = gate_probability;
  NoiseCheckStats s;
  for (int k = 0; k < runs; ++k) {
    so.seed = 300 + k;
    const SyntheticRun run = make_synthetic_run(so);
    const RefinementResult r = refine_batch(run.run, o, truth_point(run), batch);
    if (!r.noise.ok) continue;
    ++s.runs;
    s.scale += r.noise.scale;
    s.nees_model += test_support::nees(r.extrinsics, r.noise.model_covariance, run.truth);
    s.nees_checked += test_support::nees(r.extrinsics, r.noise.covariance, run.truth);
  }
  s.scale /= s.runs;
  s.nees_model /= s.runs;
  s.nees_checked /= s.runs;
  return s;
}

// Independent bearings at the assumed sigma: the check agrees with the model (scale near 1;
// 50 runs: mean 0.94), and the model covariance it builds on is the Ceres one.
// The wheel check (WheelCheck): over 20 runs whose wheels follow their model, the statistic
// averages about chi-square(2)'s 2 and the rotation scale about 0; a model whose wheel base is
// 2% short (the wheels' turns read 2% too large) is found in every run, with the scale 0.02
// within 3 sigma, and told with the wheel base that fits.
TEST(WheelCheck, FindsAWrongWheelBaseAndNothingWhereTheModelIsRight) {
  double chi2 = 0.0, scale = 0.0;
  int runs = 0, flagged = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SyntheticRunOptions so;
    so.bearing_sigma = deg2rad(0.03);
    so.seed = seed;
    const SyntheticRun run = make_synthetic_run(so);
    Options o = options_for(so);
    o.bearing_sigma = so.bearing_sigma;
    const RefinementResult r = refine_batch(run.run, o, truth_point(run));
    ASSERT_TRUE(r.noise.wheels.ok) << seed;
    chi2 += r.noise.wheels.chi2;
    scale += r.noise.wheels.rotation_scale;
    flagged += wheel_check_rejects_model(r.noise.wheels);
    ++runs;
    if (seed > 5) continue;
    Options wrong = o;
    wrong.wheel_base = so.wheel_base / 1.02;
    const RefinementResult w = refine_batch(run.run, wrong, truth_point(run));
    ASSERT_TRUE(w.noise.wheels.ok);
    EXPECT_TRUE(wheel_check_rejects_model(w.noise.wheels)) << seed << ": chi2 " << w.noise.wheels.chi2;
    EXPECT_NEAR(w.noise.wheels.rotation_scale, 0.02, 3.0 * w.noise.wheels.sigma_rotation_scale)
        << seed;
    if (seed == 1) {
      CalibrationResult cr;
      cr.refined = true;
      cr.refinement = w;
      bool told = false;
      for (const std::string& m : result_warnings(cr))
        told |= m.find("turns 2.") != std::string::npos && m.find("% larger than the robot made") != std::string::npos &&
                m.find("a wheel base of 0.5") != std::string::npos;
      EXPECT_TRUE(told);
    }
  }
  EXPECT_GT(chi2 / runs, 1.0);
  EXPECT_LT(chi2 / runs, 3.5);
  // One run's sigma of the scale is 0.25%; the mean over these runs is +0.14% (the wheels pull
  // the solution's poses a little: WheelCheck). Regressed on the wheels' own rotation it was
  // -0.22%.
  EXPECT_LT(std::abs(scale / runs), 0.002);
  EXPECT_LE(flagged, 1);
}

// Each side of the verdict at its own level: chi-square(10) / 10 has its 1% point at 0.256,
// its 30% point at 0.727 and its 99% point at 2.321.
TEST(NoiseCheck, VerdictSidesHaveTheirOwnLevels) {
  EXPECT_NEAR(noise_check_lower_limit(10, 0.01), 0.2558, 1e-3);
  EXPECT_NEAR(noise_check_lower_limit(10, 0.3), 0.7267, 1e-3);
  EXPECT_NEAR(noise_check_limit(10, 0.01), 2.3209, 1e-3);
  BatchNoiseCheck c;
  c.ok = true;
  c.clusters = 10;
  c.scale = 0.5;
  EXPECT_EQ(noise_check_verdict(c), NoiseVerdict::kAgrees);
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.3), NoiseVerdict::kLessNoise);
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.0), NoiseVerdict::kAgrees);  // 0: the side is off
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.5), NoiseVerdict::kAgrees);  // not a test
  c.scale = 0.2;
  EXPECT_EQ(noise_check_verdict(c), NoiseVerdict::kLessNoise);
  c.scale = 2.4;
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.3), NoiseVerdict::kMoreNoise);
  EXPECT_EQ(noise_check_verdict(c, 0.001, 0.3), NoiseVerdict::kAgrees);  // 99.9% point 2.959
  c.clusters = 1;
  EXPECT_EQ(noise_check_verdict(c, 0.01, 0.3), NoiseVerdict::kAgrees);
}

TEST(NoiseCheck, AgreesWithTheModelWhenTheModelIsRight) {
  const NoiseCheckStats s = noise_check_monte_carlo(0.05, 0.0, 20);
  ASSERT_EQ(s.runs, 20);
  EXPECT_GT(s.scale, 0.7);
  EXPECT_LT(s.scale, 1.3);
  EXPECT_GT(s.nees_checked, 0.5 * s.nees_model);
  EXPECT_LT(s.nees_checked, 2.0 * s.nees_model);
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.seed = 5;
  const SyntheticRun run = make_synthetic_run(so);
  const RefinementResult r = refine_batch(run.run, options_for(so), truth_point(run));
  ASSERT_TRUE(r.noise.ok);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(r.noise.model_covariance(i, i), r.covariance(i, i), 1e-3 * r.covariance(i, i));
}

// With a constant bearing error per line in the data and in the model (Options::
// track_bias_sigma), the check counts each line's bias prior as a row of that line's cluster:
// the scale stays near 1 (without that row the bias was free and the scale read 656 on a run
// from pixels), and the dense and sparse leverages agree.
TEST(NoiseCheck, AgreesWithTheModelWithPerLineBias) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.03);
  so.track_bias_sigma = deg2rad(0.03);
  Options o = options_for(so);
  o.bearing_sigma = so.bearing_sigma;
  o.track_bias_sigma = so.track_bias_sigma;
  BatchOptions sparse;
  sparse.noise_check_dense_limit = 0;
  double scale = 0.0;
  const int runs = 20;
  for (int k = 0; k < runs; ++k) {
    so.seed = 300 + k;
    const SyntheticRun run = make_synthetic_run(so);
    const RefinementResult r = refine_batch(run.run, o, truth_point(run));
    ASSERT_TRUE(r.noise.ok) << so.seed;
    scale += r.noise.scale;
    if (k < 3) {
      const RefinementResult s = refine_batch(run.run, o, truth_point(run), sparse);
      ASSERT_TRUE(s.noise.ok);
      EXPECT_NEAR(r.noise.scale, s.noise.scale, 1e-6 * r.noise.scale);
    }
  }
  scale /= runs;
  RecordProperty("scale", std::to_string(scale));
  EXPECT_GT(scale, 0.7);
  EXPECT_LT(scale, 1.3);
}

// The warning that the filter's gate refused many bearings counts the frames after the
// start-up window only: the window's own outliers (counted in its frames) are no sign of a
// filter that diverged; where the window failed, the filter ran over those frames and they
// count.
TEST(ResultWarnings, GateRefusalsCountAfterTheWindow) {
  CalibrationResult r;
  r.filter.window_frames = 10;
  r.filter.history.resize(30);
  for (int k = 0; k < 10; ++k) r.filter.history[k].num_rejected = 20;  // the window's outliers
  for (int k = 10; k < 30; ++k) r.filter.history[k].num_updates = 10;
  auto warns = [](const CalibrationResult& c) {
    for (const std::string& m : result_warnings(c))
      if (m.find("chi-square gate refused") != std::string::npos) return true;
    return false;
  };
  EXPECT_FALSE(warns(r));  // 0 of 200 after the window
  r.filter.window_failure = "window solve failed";
  EXPECT_TRUE(warns(r));  // 200 of 400 over the whole run, the EKF's own
  r.filter.window_failure.clear();
  for (int k = 10; k < 30; ++k) r.filter.history[k].num_rejected = 4;  // 80 of 280
  EXPECT_TRUE(warns(r));
  for (int k = 10; k < 30; ++k) r.filter.history[k].num_rejected = 2;  // 40 of 240
  EXPECT_FALSE(warns(r));
}

// The dense inverse (small problems) and the sparse solves (large ones) give the same check.
TEST(NoiseCheck, DenseAndSparseLeverageAgree) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.05);
  so.bearing_correlation = 0.5;
  so.seed = 9;
  const SyntheticRun run = make_synthetic_run(so);
  BatchOptions sparse;
  sparse.noise_check_dense_limit = 0;
  const RefinementResult d = refine_batch(run.run, options_for(so), truth_point(run));
  const RefinementResult s = refine_batch(run.run, options_for(so), truth_point(run), sparse);
  ASSERT_TRUE(d.noise.ok);
  ASSERT_TRUE(s.noise.ok);
  EXPECT_EQ(d.noise.clusters, s.noise.clusters);
  EXPECT_NEAR(d.noise.scale, s.noise.scale, 1e-6 * d.noise.scale);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(d.noise.covariance(i, i), s.noise.covariance(i, i), 1e-6 * d.noise.covariance(i, i));
}

// Bearings twice as noisy as assumed: the variance is four times the model's. Without the
// outlier gate and the track splitting, whose thresholds are in assumed sigmas: at the
// default gate (3.3 sigmas) a tenth of these bearings would be cut off and the rest would
// look less noisy than they are (scale 2.0), and splitting would cut clean tracks (10 per run).
TEST(NoiseCheck, FindsBearingsNoisierThanAssumed) {
  BatchOptions no_splits;
  no_splits.split_chi2 = 0.0;
  const NoiseCheckStats s =
      noise_check_monte_carlo(0.10, 0.0, 20, /*gate_probability=*/1.0, no_splits);
  ASSERT_EQ(s.runs, 20);
  EXPECT_GT(s.scale, 3.0);
  EXPECT_LT(s.scale, 5.3);
  EXPECT_GT(s.nees_model, 7.81);  // the model is overconfident by the factor 4
  // With 10 tracks the check's scale of one run is itself uncertain (about chi-square(12) /
  // 12), so the mean NEES under the checked covariance stays above 3 (measured 5.3 against
  // the model's 8.8).
  EXPECT_LT(s.nees_checked, 0.7 * s.nees_model);
  RecordProperty("scale", std::to_string(s.scale));
  RecordProperty("nees_model", std::to_string(s.nees_model));
  RecordProperty("nees_checked", std::to_string(s.nees_checked));
}

// Errors correlated along each track (AR(1), 0.9 from frame to frame), each bearing at the
// assumed sigma: the model, which takes them as independent, is overconfident (NEES 13.0);
// the check, which sums a track's errors before squaring them, much less (6.9: with 10 tracks
// one run's scale is itself uncertain).
TEST(NoiseCheck, FindsErrorsCorrelatedAlongTracks) {
  const NoiseCheckStats s = noise_check_monte_carlo(0.05, 0.9, 20);
  ASSERT_EQ(s.runs, 20);
  EXPECT_GT(s.nees_model, 7.81);
  EXPECT_GT(s.scale, 2.0);
  EXPECT_LT(s.nees_checked, 0.6 * s.nees_model);
  RecordProperty("scale", std::to_string(s.scale));
  RecordProperty("nees_model", std::to_string(s.nees_model));
  RecordProperty("nees_checked", std::to_string(s.nees_checked));
}


// Bearings four times less noisy than assumed (variance / 16), the case of a camera better
// than the default --bearing-sigma: the check finds less noise than the model assumes
// (NoiseVerdict::kLessNoise), says so and names the sigma the data want, and, the tracks being
// whole (no pieces joined), shrinks the bearings' share of the covariances. The camera's yaw
// phi + psi, which the bearings determine, then has about the right sigma (mean z^2 near 1
// instead of 0.21 under the model's). With the same bearings cut into pieces every ~10
// frames (CalibrateOptions::noise_check_lower_max_joins), the verdict is reported and the
// covariances kept.
TEST(NoiseCheck, FindsBearingsLessNoisyThanAssumed) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(0.0125);
  Options o = options_for(so);
  o.bearing_sigma = deg2rad(0.05);  // what the model assumes
  const int runs = 12;
  int less = 0, filter_less = 0, kept_broken = 0, less_broken = 0;
  double scale = 0, yaw = 0, yaw_model = 0;
  auto yaw_z2 = [](const Extrinsics& est, const Eigen::Matrix3d& c, const Extrinsics& truth) {
    const double e = angle_diff(est.phi + est.psi, truth.phi + truth.psi);
    return e * e / (c(0, 0) + c(2, 2) + 2.0 * c(0, 2));
  };
  for (int k = 0; k < runs; ++k) {
    so.seed = 400 + static_cast<std::uint64_t>(k);
    so.break_probability = 0.0;
    const SyntheticRun run = make_synthetic_run(so);
    const CalibrationResult r = calibrate(run.run, o, {.refine = true});
    ASSERT_TRUE(r.noise_checked && r.refinement.covariance_ok) << "seed " << so.seed;
    scale += r.noise.scale;
    if (r.noise_verdict == NoiseVerdict::kLessNoise) {
      ++less;
      EXPECT_LT(r.noise.scale,
                noise_check_lower_limit(r.noise.clusters, r.noise_check_lower_level));
      EXPECT_TRUE(r.noise_applied);
      EXPECT_NE(noise_check_line(r).find("less than the model assumes"), std::string::npos);
      EXPECT_NE(noise_check_line(r).find("sigmas scaled by"), std::string::npos);
      EXPECT_NE(noise_check_line(r).find("--bearing-sigma"), std::string::npos);
      // The bearings' share only: the yaw's variance shrinks, and the whole stays positive
      // definite.
      EXPECT_LT(r.refinement.covariance(0, 0) + r.refinement.covariance(2, 2) +
                    2.0 * r.refinement.covariance(0, 2),
                r.refinement_model_covariance(0, 0) + r.refinement_model_covariance(2, 2) +
                    2.0 * r.refinement_model_covariance(0, 2));
      EXPECT_EQ(Eigen::LLT<Eigen::Matrix3d>(r.refinement.covariance).info(), Eigen::Success);
    } else {
      EXPECT_EQ(r.refinement.covariance, r.refinement_model_covariance);
    }
    if (r.filter_noise_verdict == NoiseVerdict::kLessNoise) {
      ++filter_less;
      EXPECT_TRUE(r.filter_noise_applied);
      EXPECT_EQ(Eigen::LLT<Eigen::Matrix3d>(r.filter.covariance).info(), Eigen::Success);
    }
    yaw += yaw_z2(r.refinement.extrinsics, r.refinement.covariance, run.truth);
    yaw_model += yaw_z2(r.refinement.extrinsics, r.refinement_model_covariance, run.truth);
    // The same bearings in pieces: kept.
    so.break_probability = 0.1;
    const SyntheticRun broken = make_synthetic_run(so);
    const CalibrationResult b = calibrate(broken.run, o, {.refine = true});
    ASSERT_TRUE(b.noise_checked && b.refinement.covariance_ok) << "seed " << so.seed;
    if (b.noise_verdict == NoiseVerdict::kLessNoise) {
      ++less_broken;
      EXPECT_GT(static_cast<double>(b.refinement.merges.size()), 0.5 * b.noise.clusters);
      kept_broken += !b.noise_applied && b.refinement.covariance == b.refinement_model_covariance;
      EXPECT_NE(noise_check_line(b).find("pieces of lines were joined"), std::string::npos);
    }
  }
  scale /= runs;
  yaw /= runs;
  yaw_model /= runs;
  RecordProperty("scale", std::to_string(scale));
  RecordProperty("yaw_z2", std::to_string(yaw));
  RecordProperty("yaw_z2_model", std::to_string(yaw_model));
  RecordProperty("less_broken", std::to_string(less_broken));
  // Measured (session 13): 10 of 12 runs below the limit (chi-square(G) / G's 1% point, 0.26
  // for 10 tracks), the filter's check too in 10; scale 0.18 in the mean (the bearings'
  // variance is 1/16 of the model's; the rest is the check's spread over 10 tracks); the
  // yaw's mean squared normalised error 0.21 under the model, 0.99 under the covariance
  // shrunk by the check.
  EXPECT_GE(less, 9);
  EXPECT_GE(filter_less, 9);
  EXPECT_LT(scale, 0.4);
  EXPECT_LT(yaw_model, 0.5);
  EXPECT_GT(yaw, 0.5);
  EXPECT_LT(yaw, 2.0);
  EXPECT_EQ(kept_broken, less_broken);
}
}  // namespace
}  // namespace omnivert::calib
