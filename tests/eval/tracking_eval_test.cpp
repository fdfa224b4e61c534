#include "omnivert/eval/tracking_eval.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "omnivert/core/error.hpp"

namespace omnivert {
namespace {

TrackRow det(std::int64_t frame, std::int64_t id, double bearing, std::int64_t matched = -1) {
  TrackRow r;
  r.frame = frame;
  r.track_id = id;
  r.bearing = bearing;
  r.matched_frame = matched;
  return r;
}

eval::GroundTruthLine gt(std::int64_t frame, std::int64_t id, double bearing, double len = 90.0) {
  eval::GroundTruthLine g;
  g.frame = frame;
  g.line_id = id;
  g.bearing = bearing;
  g.r_inner = 10.0;
  g.r_outer = 10.0 + len;
  return g;
}

eval::TrackingEvalOptions options() {
  eval::TrackingEvalOptions o;
  o.annulus_r_min = 0.0;
  o.annulus_r_max = 100.0;
  return o;
}

// World line A at bearing 0, B at 0.5 rad, frames 0..4. Hand-built tracks with one false
// match (track 0 jumps from A to B), one false new entry (track 2 restarts A two frames after
// its last detection), and a clutter track (unverified link).
struct Case {
  std::vector<eval::GroundTruthLine> truth;
  std::vector<TrackRow> tracks;
};

Case hand_built() {
  Case c;
  for (int f = 0; f < 5; ++f) {
    c.truth.push_back(gt(f, 100, 0.0));
    c.truth.push_back(gt(f, 200, 0.5, f == 4 ? 50.0 : 90.0));  // short in frame 4
  }
  c.tracks = {
      det(0, 0, 0.005),
      det(1, 0, 0.005, 0),
      det(2, 0, 0.005, 1),
      det(3, 0, 0.51, 2),  // false match A -> B
      det(0, 1, 0.5),
      det(1, 1, 0.5, 0),
      det(2, 1, 0.5, 1),
      det(4, 2, 0.005),  // false new entry
      det(1, 3, 2.0),
      det(2, 3, 2.0, 1),  // clutter
  };
  return c;
}

TEST(TrackingEval, OptionsValidation) {
  std::string error;
  EXPECT_FALSE(eval::TrackingEvalOptions{}.IsValid(&error));  // the annulus is required
  EXPECT_NE(error.find("annulus"), std::string::npos);
  EXPECT_TRUE(options().IsValid(&error));
  eval::TrackingEvalOptions o = options();
  o.association_tolerance = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
}

TEST(TrackingEval, HandBuiltCounts) {
  const Case c = hand_built();
  eval::TrackingEvalOptions o = options();
  const eval::TrackingEvaluation ev = eval::evaluate_tracking(c.tracks, c.truth, o);
  EXPECT_EQ(ev.total.matches, 6);
  EXPECT_EQ(ev.total.correct, 4);
  EXPECT_EQ(ev.total.false_matches, 1);
  EXPECT_EQ(ev.total.unverified, 1);
  EXPECT_EQ(ev.total.new_entries, 4);
  EXPECT_EQ(ev.total.false_new_entries, 1);
  EXPECT_EQ(ev.total.denominator(), 7);
  EXPECT_NEAR(ev.total.percent_correct(), 400.0 / 7.0, 1e-9);
  EXPECT_NEAR(ev.total.percent_false_matches(), 100.0 / 7.0, 1e-9);
  EXPECT_NEAR(ev.total.percent_false_new_entries(), 100.0 / 7.0, 1e-9);
  EXPECT_NEAR(ev.total.percent_correct() + ev.total.percent_false_matches() +
                  ev.total.percent_false_new_entries() + ev.total.percent_unverified(),
              100.0,
              1e-9);
  EXPECT_EQ(ev.detections, 10);
  EXPECT_EQ(ev.associated_detections, 8);
  // Long rows: 9 (B is short in frame 4); detected: A in 0,1,2,4 and B in 0,1,2,3.
  EXPECT_EQ(ev.long_lines, 9);
  EXPECT_EQ(ev.long_lines_detected, 8);
  // Errors: 0.005 four times, 0.01 once, 0 three times: RMS sqrt(2e-4 / 8) = 0.005.
  EXPECT_NEAR(ev.bearing_rms, 0.005, 1e-9);
  EXPECT_EQ(ev.duplicate_ids, 0);
  EXPECT_EQ(ev.off_majority_detections, 1);  // track 0's last detection, on B
}

// Rule 8: a track that slips from line A onto line B close behind it (bearings within the
// tolerance of both around the slip, then apart) is no false match by rule 3 (while the two
// lines are within the tolerance either could be the one followed), but its three detections
// on A are off its majority line (B: five detections).
TEST(TrackingEval, SlipOntoACloseLineCountsEveryDetectionAfterIt) {
  std::vector<eval::GroundTruthLine> truth;
  std::vector<TrackRow> tracks;
  for (int f = 0; f < 8; ++f) {
    const double b = 0.002 + 0.004 * f;  // B drifts away from A at 0
    truth.push_back(gt(f, 1, 0.0));
    truth.push_back(gt(f, 2, b));
    tracks.push_back(det(f, 7, f < 3 ? 0.0 : b, f > 0 ? f - 1 : -1));
  }
  const eval::TrackingEvaluation ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.total.matches, 7);
  EXPECT_EQ(ev.total.false_matches, 0);
  EXPECT_EQ(ev.total.correct, 7);
  EXPECT_EQ(ev.off_majority_detections, 3);
  EXPECT_NE(eval::format_tracking_table(ev).find("majority world line: 3"), std::string::npos);
}

TEST(TrackingEval, PerIntervalRows) {
  const Case c = hand_built();
  eval::TrackingEvalOptions o = options();
  o.interval = 2;
  const eval::TrackingEvaluation ev = eval::evaluate_tracking(c.tracks, c.truth, o);
  ASSERT_EQ(ev.intervals.size(), 3u);
  EXPECT_EQ(ev.intervals[0].first_frame, 0);
  EXPECT_EQ(ev.intervals[2].end_frame, 5);
  EXPECT_EQ(ev.intervals[0].matches, 2);
  EXPECT_EQ(ev.intervals[0].correct, 2);
  EXPECT_EQ(ev.intervals[0].new_entries, 3);
  EXPECT_EQ(ev.intervals[1].matches, 4);
  EXPECT_EQ(ev.intervals[1].false_matches, 1);
  EXPECT_EQ(ev.intervals[1].unverified, 1);
  EXPECT_EQ(ev.intervals[2].matches, 0);
  EXPECT_EQ(ev.intervals[2].false_new_entries, 1);
  EXPECT_NEAR(ev.intervals[2].percent_false_new_entries(), 100.0, 1e-9);
  const std::string table = eval::format_tracking_table(ev);
  EXPECT_NE(table.find("0-2"), std::string::npos);
  EXPECT_NE(table.find("4-5"), std::string::npos);
  EXPECT_NE(table.find("Total"), std::string::npos);
  EXPECT_NE(table.find("Recall of long lines: 88.89%"), std::string::npos) << table;
}

TEST(TrackingEval, FalseNewEntryNeedsRecentDetection) {
  const Case c = hand_built();
  eval::TrackingEvalOptions o = options();
  o.look_back = 1;  // A was last detected 2 frames before track 2 starts
  EXPECT_EQ(eval::evaluate_tracking(c.tracks, c.truth, o).total.false_new_entries, 0);
  o.look_back = 2;
  EXPECT_EQ(eval::evaluate_tracking(c.tracks, c.truth, o).total.false_new_entries, 1);
}

// Rule 9: a person's side at 0.3 deg from line A (0.2 deg from the side) in frames 1-3 and a
// new track on it in each frame. Without the occluders each new track is taken for A, seen the
// frame before: three false new entries (and the side's links false matches when linked to
// A's track). With them the side's detections are left out: none.
TEST(TrackingEval, OccluderSidesAreLeftOut) {
  std::vector<eval::GroundTruthLine> truth;
  std::vector<eval::OccluderBearing> occluders;
  std::vector<TrackRow> tracks;
  const double side = deg2rad(0.5), a = deg2rad(0.2);
  for (int f = 0; f < 4; ++f) {
    truth.push_back(gt(f, 100, 0.0));
    tracks.push_back(det(f, 0, 0.0, f > 0 ? f - 1 : -1));
    if (f > 0) {
      occluders.push_back({f, side});
      tracks.push_back(det(f, 10 + f, side - a));  // a new track on the side every frame
    }
  }
  const eval::TrackingEvaluation without = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(without.total.false_new_entries, 3);
  const eval::TrackingEvaluation with =
      eval::evaluate_tracking(tracks, truth, options(), occluders);
  EXPECT_EQ(with.total.false_new_entries, 0);
  EXPECT_EQ(with.total.matches, 3);
  EXPECT_EQ(with.total.correct, 3);
  EXPECT_EQ(with.occluder_detections, 3);
  EXPECT_EQ(with.occluder_new_tracks, 3);
  // A detection nearer to the line than to the side stays the line's.
  std::vector<TrackRow> on_line = {det(1, 0, deg2rad(0.1))};
  EXPECT_EQ(eval::evaluate_tracking(on_line, truth, options(), occluders).occluder_detections, 0);
}

TEST(TrackingEval, AssociationToleranceAndWrap) {
  std::vector<eval::GroundTruthLine> truth = {gt(0, 1, 3.14), gt(0, 2, 1.0)};
  // -3.14 is 0.0032 rad from 3.14 across the wrap: associated. 1.0 + 1.1 deg: not.
  std::vector<TrackRow> tracks = {det(0, 0, -3.14), det(0, 1, 1.0 + deg2rad(1.1))};
  const eval::TrackingEvaluation ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.associated_detections, 1);
  EXPECT_NEAR(ev.bearing_rms, 2 * kPi - 6.28, 1e-9);
  EXPECT_EQ(ev.long_lines_detected, 1);
}

// A link is to the observation the tracker matched (matched_frame), not simply the previous
// detection of the id; without matched_frame the previous detection is used.
TEST(TrackingEval, LinksFollowMatchedFrame) {
  std::vector<eval::GroundTruthLine> truth;
  for (int f = 0; f < 3; ++f) {
    truth.push_back(gt(f, 1, 0.0));
    truth.push_back(gt(f, 2, 1.0));
  }
  std::vector<TrackRow> tracks = {det(0, 7, 0.0), det(1, 7, 1.0, 0), det(2, 7, 0.0, 0)};
  eval::TrackingEvaluation ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.total.matches, 2);
  EXPECT_EQ(ev.total.correct, 1);        // 2 -> 0
  EXPECT_EQ(ev.total.false_matches, 1);  // 1 -> 0
  for (auto& r : tracks) r.matched_frame = -1;
  ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.total.false_matches, 2);  // 1 -> 0 and 2 -> 1
}

// Two detections of one frame under one id (a double claim): one of them is a false match.
TEST(TrackingEval, DoubleClaimCountsAsFalseMatch) {
  std::vector<eval::GroundTruthLine> truth = {gt(0, 1, 0.0), gt(1, 1, 0.0), gt(1, 2, 0.2)};
  std::vector<TrackRow> tracks = {det(0, 3, 0.0), det(1, 3, 0.0, 0), det(1, 3, 0.2, 0)};
  const eval::TrackingEvaluation ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.duplicate_ids, 1);
  EXPECT_EQ(ev.total.matches, 2);
  EXPECT_EQ(ev.total.correct, 1);
  EXPECT_EQ(ev.total.false_matches, 1);
}

// A double claim while the scene turns 3 degrees a frame and the two lines are 2 degrees
// apart: by nearest bearing each link of frame 2 would be taken from the wrong line of frame
// 1 (two false matches); with the matched line named (line, matched_line) both are correct.
TEST(TrackingEval, DoubleClaimDuringTurnUsesMatchedLine) {
  const double deg = kPi / 180.0;
  std::vector<eval::GroundTruthLine> truth;
  for (int f = 0; f < 3; ++f) {
    truth.push_back(gt(f, 1, -3.0 * f * deg));
    truth.push_back(gt(f, 2, (2.0 - 3.0 * f) * deg));
  }
  auto row =
      [&](std::int64_t frame, int line, double bearing, std::int64_t matched, int matched_line) {
        TrackRow r = det(frame, 5, bearing, matched);
        r.line = line;
        r.matched_line = matched_line;
        return r;
      };
  std::vector<TrackRow> tracks = {row(0, 0, 0.0, -1, -1),
                                  row(0, 1, 2.0 * deg, -1, -1),
                                  row(1, 0, -3.0 * deg, 0, 0),
                                  row(1, 1, -1.0 * deg, 0, 1),
                                  row(2, 0, -6.0 * deg, 1, 0),
                                  row(2, 1, -4.0 * deg, 1, 1)};
  eval::TrackingEvaluation ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.total.matches, 4);
  EXPECT_EQ(ev.total.correct, 4);
  EXPECT_EQ(ev.total.false_matches, 0);
  for (auto& r : tracks) r.matched_line = -1;  // the old file format: nearest bearing
  ev = eval::evaluate_tracking(tracks, truth, options());
  EXPECT_EQ(ev.total.false_matches, 2);
}

// Two lines cross (within 1 degree of each other in frame 2) and the tracks swap there:
// one false match per track, where the lines separate; no false match while they are
// indistinguishable, and none for tracks that follow their line through the crossing.
TEST(TrackingEval, SwapAtCrossingCountsOnceAndAmbiguityIsNotAnError) {
  const double a_deg[] = {-2, -1, 0, 1, 2}, b_deg[] = {2, 1, 0.05, -1, -2};
  std::vector<eval::GroundTruthLine> truth;
  for (int f = 0; f < 5; ++f) {
    truth.push_back(gt(f, 1, deg2rad(a_deg[f])));
    truth.push_back(gt(f, 2, deg2rad(b_deg[f])));
  }
  std::vector<TrackRow> swap, follow;
  for (int f = 0; f < 5; ++f) {
    const std::int64_t m = f > 0 ? f - 1 : -1;
    // Swapping tracks: up to frame 2 on their own line, then on the other one.
    swap.push_back(det(f, 0, deg2rad(f <= 2 ? a_deg[f] : b_deg[f]), m));
    swap.push_back(det(f, 1, deg2rad(f <= 2 ? b_deg[f] : a_deg[f]), m));
    follow.push_back(det(f, 0, deg2rad(a_deg[f]), m));
    follow.push_back(det(f, 1, deg2rad(b_deg[f]), m));
  }
  eval::TrackingEvaluation ev = eval::evaluate_tracking(swap, truth, options());
  EXPECT_EQ(ev.ambiguous_detections, 2);
  EXPECT_EQ(ev.total.matches, 8);
  EXPECT_EQ(ev.total.false_matches, 2);
  EXPECT_EQ(ev.total.correct, 6);
  ev = eval::evaluate_tracking(follow, truth, options());
  EXPECT_EQ(ev.total.false_matches, 0);
  EXPECT_EQ(ev.total.correct, 8);
}

TEST(TrackingEval, EmptyInputs) {
  const eval::TrackingEvaluation ev = eval::evaluate_tracking({}, {}, options());
  EXPECT_EQ(ev.total.matches, 0);
  EXPECT_EQ(ev.total.percent_correct(), 0.0);
  EXPECT_EQ(ev.long_line_recall(), 0.0);
  EXPECT_FALSE(std::isnan(ev.bearing_rms));
  EXPECT_NE(eval::format_tracking_table(ev).find("Total"), std::string::npos);
}

}  // namespace
}  // namespace omnivert

namespace omnivert {
namespace {

TEST(TrackingEval, InvalidOptionsThrowInputError) {
  EXPECT_THROW(eval::evaluate_tracking({}, {}, eval::TrackingEvalOptions{}), InputError);
}

}  // namespace
}  // namespace omnivert
