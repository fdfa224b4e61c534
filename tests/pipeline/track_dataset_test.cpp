// track_dataset and read_tracks_for_dataset on a tiny simulated dataset (12 frames of the
// paper's trajectory in the corridor, as `omnivert simulate --world corridor --trajectory
// paper --frames 12 --seed 1` renders it): end to end against the ground truth, a corrupt,
// missing or line-less image in the middle (warned about, tracking goes on and bridges the
// gap), datasets without images (a clear InputError), and the same tracks for every thread
// count.

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/eval/tracking_eval.hpp"
#include "omnivert/match/tracks_io.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "omnivert/viz/tracks_plot.hpp"
#include "simulated_datasets.hpp"

namespace omnivert::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The dataset loaded as `omnivert track` loads it: wheel data optional, a missing image
// recorded (and skipped when tracked).
dataset::Dataset load_for_tracking(const fs::path& dir) {
  dataset::LoadOptions lo;
  lo.require_wheel = false;
  lo.allow_missing_images = true;
  return dataset::Dataset::load(dir.string(), lo);
}

// The options `omnivert track` passes without flags (tools/cmd_track.cpp).
pipeline::TrackDatasetOptions cli_track_options() { return {}; }

std::set<std::int64_t> frames_of(const std::vector<TrackRow>& rows) {
  std::set<std::int64_t> frames;
  for (const TrackRow& r : rows) frames.insert(r.frame);
  return frames;
}

// `omnivert evaluate`: the tracks against the dataset's ground-truth lines (Table 3).
eval::TrackingEvaluation evaluate(const dataset::Dataset& data, const std::vector<TrackRow>& rows) {
  const auto& gt = data.ground_truth();
  EXPECT_TRUE(gt && gt->has_lines);
  std::vector<eval::GroundTruthLine> truth;
  for (const auto& l : gt->lines)
    truth.push_back({l.frame, l.line_id, l.bearing, l.r_inner, l.r_outer});
  eval::TrackingEvalOptions o;
  o.annulus_r_min = data.camera().r_min.value_or(0.0);
  o.annulus_r_max = data.camera().r_max.value_or(0.0);
  o.num_frames = static_cast<std::int64_t>(data.size());
  return eval::evaluate_tracking(rows, truth, o);
}

class TrackDataset : public SimulatedDatasets {
 protected:
  static fs::path tiny() { return dataset("track12", {"corridor", "paper", 1, 12}); }
  // A copy of the tiny dataset to damage, and its image file names.
  static fs::path tiny_copy(const std::string& name) {
    const fs::path dir = scratch(name);
    copy_dataset(tiny(), dir);
    return dir;
  }
  // Frame 5 of 12 damaged: tracking goes on to frame 11, frame 5 has no lines, and the
  // look-back bridges the gap (some line of frame 6 continues a track from frame 4).
  static void expect_frame_5_skipped_and_bridged(const fs::path& dir,
                                                 const pipeline::TrackDatasetResult& r) {
    EXPECT_EQ(r.frames, 12);
    const std::set<std::int64_t> frames = frames_of(r.rows);
    for (std::int64_t f : {0, 1, 2, 3, 4, 6, 7, 8, 9, 10, 11})
      EXPECT_TRUE(frames.count(f)) << "no rows for frame " << f;
    EXPECT_FALSE(frames.count(5)) << "frame 5 should have no lines";
    const auto bridged = std::count_if(r.rows.begin(), r.rows.end(), [](const TrackRow& row) {
      return row.frame == 6 && row.matched_frame == 4;
    });
    EXPECT_GE(bridged, 3) << "lines of frame 6 matched across the gap to frame 4";
    const auto data = load_for_tracking(dir);
    EXPECT_GT(evaluate(data, r.rows).total.matches, 0);
  }
};

// 12 frames of a straight drive in the corridor: about 6 lines a frame, all tracked, none
// falsely matched, bearings to better than 0.05 degree RMS.
TEST_F(TrackDataset, TinyRunIsTrackedInEveryFrameAndMatchesTheGroundTruth) {
  const auto data = load_for_tracking(tiny());
  const pipeline::TrackDatasetResult r = pipeline::track_dataset(data, cli_track_options());
  EXPECT_EQ(r.frames, 12);
  EXPECT_EQ(r.frames_skipped, 0);
  EXPECT_EQ(frames_of(r.rows).size(), 12u);

  const fs::path out = scratch("tiny-out");
  fs::create_directories(out);
  write_tracks_csv(out / "tracks.csv", r.rows);
  viz::write_tracks_png(out / "tracks.png", r.rows);
  EXPECT_THAT(read_lines(out / "tracks.csv").front(),
              ::testing::StartsWith("frame,timestamp_ns,track_id,bearing_rad"));
  EXPECT_GE(fs::file_size(out / "tracks.png"), 1000u);

  const eval::TrackingEvaluation ev = evaluate(data, r.rows);
  EXPECT_GE(ev.total.matches, 40);
  EXPECT_GE(ev.total.percent_correct(), 95.0);
  EXPECT_EQ(ev.total.false_matches, 0);
  EXPECT_LT(rad2deg(ev.bearing_rms), 0.05);
  EXPECT_THAT(eval::format_tracking_table(ev), HasSubstr("Total"));
}

TEST_F(TrackDataset, TracksReadBackForTheSameDatasetAreTheTrackedOnes) {
  const auto data = load_for_tracking(tiny());
  const pipeline::TrackDatasetResult r = pipeline::track_dataset(data, cli_track_options());
  const fs::path file = scratch("read-back.csv");
  write_tracks_csv(file, r.rows);
  const pipeline::TrackDatasetResult back = pipeline::read_tracks_for_dataset(file.string(), data);
  ASSERT_EQ(back.rows.size(), r.rows.size());
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    EXPECT_EQ(back.rows[i].frame, r.rows[i].frame);
    EXPECT_EQ(back.rows[i].track_id, r.rows[i].track_id);
    EXPECT_NEAR(back.rows[i].bearing, r.rows[i].bearing, 1e-8);
  }
  EXPECT_EQ(back.frames, 12);
  EXPECT_EQ(back.stats.new_tracks, r.stats.new_tracks);
}

TEST_F(TrackDataset, CorruptImageIsWarnedAboutAndSkipped) {
  const fs::path dir = tiny_copy("corrupt");
  const std::string victim = image_names(dir)[5];
  write_text(dir / "cam0/data" / victim, "this is not a PNG file\n");
  const pipeline::TrackDatasetResult r =
      pipeline::track_dataset(load_for_tracking(dir), cli_track_options());
  EXPECT_EQ(r.frames_skipped, 1);
  EXPECT_THAT(joined(r.warnings),
              HasSubstr(victim + ": cannot be read as an image; frame 5 skipped"));
  expect_frame_5_skipped_and_bridged(dir, r);
}

TEST_F(TrackDataset, MissingImageIsWarnedAboutAndSkipped) {
  const fs::path dir = tiny_copy("missing");
  const std::string victim = image_names(dir)[5];
  fs::remove(dir / "cam0/data" / victim);
  const pipeline::TrackDatasetResult r =
      pipeline::track_dataset(load_for_tracking(dir), cli_track_options());
  EXPECT_EQ(r.frames_skipped, 1);
  EXPECT_THAT(joined(r.warnings),
              HasSubstr("image file '" + victim + "' not found in cam0/data/; frame 5 skipped"));
  expect_frame_5_skipped_and_bridged(dir, r);
}

// A uniform grey frame (lens cap, dark corridor) is a valid image without lines, not an
// unreadable one.
TEST_F(TrackDataset, FrameWithoutLinesIsNotReportedUnreadable) {
  const fs::path dir = tiny_copy("grey");
  write_grey_frame(dir / "cam0/data" / image_names(dir)[5]);
  const pipeline::TrackDatasetResult r =
      pipeline::track_dataset(load_for_tracking(dir), cli_track_options());
  EXPECT_THAT(joined(r.warnings), Not(HasSubstr("cannot be read")));
  expect_frame_5_skipped_and_bridged(dir, r);
}

// Every field of two track tables, exactly (the thread count must not change a bit).
void expect_identical_rows(const std::vector<TrackRow>& a,
                           const std::vector<TrackRow>& b,
                           const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const TrackRow &x = a[i], &y = b[i];
    const bool same =
        x.frame == y.frame && x.timestamp_ns == y.timestamp_ns && x.track_id == y.track_id &&
        x.bearing == y.bearing && x.image_angle == y.image_angle &&
        x.edge_pixels == y.edge_pixels && x.r_inner == y.r_inner && x.r_outer == y.r_outer &&
        x.matched_frame == y.matched_frame && x.distance == y.distance && x.line == y.line &&
        x.matched_line == y.matched_line && x.crowded == y.crowded;
    ASSERT_TRUE(same) << what << ": row " << i << " differs (frame " << x.frame << ")";
  }
}

// Frames are read and described on several threads and located in order (the centre search
// of each frame starts from the previous one, Sec. 2 step 1): the tracks, the warnings and
// the counts are the same, bit for bit, for 1, 2, 3 and 7 threads. On the centre as the
// simulator writes it in sensor.yaml, on the centre searched frame after frame (no centre in
// sensor.yaml), and with a damaged frame in the middle.
TEST_F(TrackDataset, TracksAreIdenticalForEveryThreadCount) {
  const fs::path searched = tiny_copy("threads-searched");
  std::string yaml;
  for (const std::string& line : read_lines(searched / "cam0/sensor.yaml"))
    if (line.rfind("center:", 0) != 0) yaml += line + "\n";
  write_text(searched / "cam0/sensor.yaml", yaml);
  const fs::path damaged = tiny_copy("threads-damaged");
  write_text(damaged / "cam0/data" / image_names(damaged)[5], "not an image\n");
  for (const fs::path& dir : {tiny(), searched, damaged}) {
    const auto data = load_for_tracking(dir);
    pipeline::TrackDatasetOptions o = cli_track_options();
    o.threads = 1;
    const pipeline::TrackDatasetResult one = pipeline::track_dataset(data, o, {}, true);
    ASSERT_EQ(one.frames, 12);
    EXPECT_GE(one.rows.size(), 40u) << dir;
    for (int threads : {2, 3, 7}) {
      o.threads = threads;
      const pipeline::TrackDatasetResult r = pipeline::track_dataset(data, o, {}, true);
      const std::string what =
          dir.filename().string() + ", " + std::to_string(threads) + " threads";
      expect_identical_rows(one.rows, r.rows, what);
      EXPECT_EQ(r.warnings, one.warnings) << what;
      EXPECT_EQ(r.frames_skipped, one.frames_skipped) << what;
      EXPECT_EQ(r.stats.new_tracks, one.stats.new_tracks) << what;
      ASSERT_EQ(r.features.size(), one.features.size()) << what;
      for (std::size_t f = 0; f < r.features.size(); ++f) {
        EXPECT_EQ(r.features[f].circle.center, one.features[f].circle.center) << what;
        EXPECT_TRUE(r.features[f].descriptors == one.features[f].descriptors) << what << f;
      }
    }
  }
}

TEST_F(TrackDataset, DatasetWithoutImagesIsAnInputErrorNamingCam0DataCsv) {
  const fs::path dir = tiny_copy("empty");
  write_text(dir / "cam0/data.csv", "#timestamp [ns],filename\n");
  try {
    load_for_tracking(dir);
    ADD_FAILURE() << "an empty dataset loaded";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cam0/data.csv: no images listed"));
  }
}

TEST_F(TrackDataset, DatasetWhoseImageFilesAreAllMissingIsAnInputError) {
  const fs::path dir = tiny_copy("all-missing");
  for (const std::string& name : image_names(dir)) fs::remove(dir / "cam0/data" / name);
  try {
    pipeline::track_dataset(load_for_tracking(dir), cli_track_options());
    ADD_FAILURE() << "a dataset without image files was tracked";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cam0/data.csv: none of the 12 listed image files exists"));
  }
}

}  // namespace
}  // namespace omnivert::testing
