// The tracker (Sec. 9.1): ids over a sequence, look-back, the mutual constraint, options
// and the frame contract. Gate and polarity: tracker_gate_test.cpp; continuity and the F1
// rules: tracker_continuity_test.cpp.
#include "omnivert/match/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "tracker_sequence.hpp"

namespace omnivert {
namespace {

using namespace tracker_testing;

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
