// End to end: simulate, read back with the dataset reader, and check the ground truth is
// self-consistent: the wheel travel integrated with eq. (14)-(15) reproduces
// ground_truth/poses.csv, the lines' bearings follow from the edges, the poses and the
// extrinsics (docs/theory/conventions.md), runs are reproducible, and no partial dataset is left
// behind.

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "calib/batch_point.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/match/tracks_io.hpp"
#include "omnivert/pipeline/calibration_input.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::sim {
namespace {

namespace fs = std::filesystem;

class SimulatorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_sim_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every ground-truth line's bearing follows from edges.csv, the pose and the extrinsics.
void expect_lines_follow_edges(const fs::path& out, const auto& gt, const SimConfig& cfg) {
  std::map<int, Eigen::Vector2d> edges;
  {
    std::ifstream in(fs::path(out) / "ground_truth" / "edges.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      int id;
      double ex, ey, z0, z1;
      ASSERT_EQ(std::sscanf(line.c_str(), "%d,%lf,%lf,%lf,%lf", &id, &ex, &ey, &z0, &z1), 5);
      edges[id] = {ex, ey};
    }
  }
  ASSERT_FALSE(gt.lines.empty());
  const auto& X = *gt.extrinsics;
  for (const auto& l : gt.lines) {
    const auto& p = gt.poses[static_cast<std::size_t>(l.frame)];
    const double xc = p.x + X.rho * std::cos(p.theta + X.phi),
                 yc = p.y + X.rho * std::sin(p.theta + X.phi);
    const Eigen::Vector2d f = edges.at(l.line_id);
    const double beta = std::atan2(f.y() - yc, f.x() - xc) - (p.theta + X.phi + X.psi);
    ASSERT_NEAR(angle_diff(l.bearing, beta), 0.0, 1e-6);
    ASSERT_GE(l.r_inner, cfg.camera.r_min - 1e-3);
    ASSERT_LE(l.r_outer, cfg.camera.r_max + 1e-3);
  }
}

void expect_short_lines_left_out(const dataset::Dataset& d,
                                 const std::vector<TrackRow>& rows,
                                 const pipeline::DatasetRun& run) {
  // Lines shorter than DatasetRunOptions::min_annulus_fraction are tracked, not used: every
  // third track is short all along; the longest track is short for frames 30-39, so its
  // bearings after them form a new track (its id above every track id); the last row's
  // fraction is not known (used).
  std::map<std::int64_t, int> rows_of;
  for (const TrackRow& r : rows) ++rows_of[r.track_id];
  std::int64_t longest = -1, max_id = -1, second = -1;
  for (const auto& [id, k] : rows_of) {
    if (id % 3 != 1 && (longest < 0 || k > rows_of[longest])) longest = id;
    max_id = std::max(max_id, id);
  }
  // Another track short in frames 50 and 51 only (fewer than split_after_short, 3): it keeps
  // its id; with split_after_short 2 it is cut there.
  std::map<std::int64_t, int> spans;  // bits: rows before frame 50, at 50, at 51, after 51
  for (const TrackRow& r : rows)
    spans[r.track_id] |= r.frame < 50 ? 1 : r.frame == 50 ? 2 : r.frame == 51 ? 4 : 8;
  for (const auto& [id, k] : rows_of)
    if (id % 3 != 1 && id != longest && spans[id] == 15 && (second < 0 || k > rows_of[second]))
      second = id;
  ASSERT_GE(second, 0);
  std::vector<TrackRow> mixed = rows;
  for (TrackRow& r : mixed) {
    const bool is_short = r.track_id % 3 == 1 ||
                          (r.track_id == longest && r.frame >= 30 && r.frame < 40) ||
                          (r.track_id == second && (r.frame == 50 || r.frame == 51));
    r.annulus_fraction = is_short ? 0.3 : 0.7;
  }
  mixed.back().annulus_fraction = std::numeric_limits<double>::quiet_NaN();  // not known: used
  // The plain count: rows not short, in pieces of at least two of them.
  auto used = [](const TrackRow& r) { return !(r.annulus_fraction < 0.5); };
  std::map<std::pair<std::int64_t, bool>, int> long_rows;  // (track, after frame 39)
  int short_rows = 0, used_rows = 0;
  auto piece = [&](const TrackRow& r) {
    return std::make_pair(r.track_id, r.track_id == longest && r.frame >= 40);
  };
  for (const TrackRow& r : mixed) {
    short_rows += !used(r);
    long_rows[piece(r)] += used(r);
  }
  for (const TrackRow& r : mixed) used_rows += used(r) && long_rows[piece(r)] >= 2;
  ASSERT_GE((long_rows[{longest, true}]), 2);
  ASSERT_GE((long_rows[{longest, false}]), 2);
  pipeline::DatasetRunOptions half;
  half.enough_tracks = 0;  // 0.5 whatever the number of tracks
  const pipeline::DatasetRun sel = pipeline::calibration_run_from_tracks(d, mixed, half);
  EXPECT_GT(short_rows, 0);
  EXPECT_EQ(sel.short_bearings, short_rows);
  EXPECT_EQ(sel.observations, used_rows);
  EXPECT_DOUBLE_EQ(sel.min_annulus_fraction, 0.5);
  int second_after = 0;
  for (std::size_t k = 0; k < sel.run.frames.size(); ++k)
    for (const auto& ob : sel.run.frames[k].observations) {
      EXPECT_TRUE(ob.track_id > max_id || ob.track_id % 3 != 1 ||
                  ob.track_id == mixed.back().track_id);
      if (ob.track_id == longest) {
        EXPECT_LT(k, 30u);  // after frame 39: a new id
      }
      if (ob.track_id == second && k > 51) ++second_after;
    }
  EXPECT_GT(second_after, 0);  // the same id after its two short frames
  pipeline::DatasetRunOptions cut_at_two = half;
  cut_at_two.split_after_short = 2;
  const pipeline::DatasetRun two = pipeline::calibration_run_from_tracks(d, mixed, cut_at_two);
  EXPECT_EQ(two.split_after_short, 2);
  EXPECT_EQ(two.observations, sel.observations);
  int second_before = 0;
  second_after = 0;
  for (std::size_t k = 0; k < two.run.frames.size(); ++k)
    for (const auto& ob : two.run.frames[k].observations)
      if (ob.track_id == second) ++(k < 50 ? second_before : second_after);
  EXPECT_GT(second_before, 0);
  EXPECT_EQ(second_after, 0);  // a new id after frame 51
  pipeline::DatasetRunOptions all;
  all.min_annulus_fraction = 0.0;
  const pipeline::DatasetRun every = pipeline::calibration_run_from_tracks(d, mixed, all);
  EXPECT_EQ(every.short_bearings, 0);
  EXPECT_EQ(every.observations, run.observations);

  // Too few tracks of long lines: the shorter ones are used, with a warning. The fractions
  // here are 0.3 and 0.7, so 0.35 gives what 0.5 gives and 0.25 gives every track.
  pipeline::DatasetRunOptions want_more;
  want_more.enough_tracks = sel.tracks + 1;
  const pipeline::DatasetRun more = pipeline::calibration_run_from_tracks(d, mixed, want_more);
  EXPECT_DOUBLE_EQ(more.min_annulus_fraction, 0.25);
  EXPECT_EQ(more.short_bearings, 0);
  EXPECT_EQ(more.observations, run.observations);
  int doubled = 0;  // the lines shorter than 0.5: sigma x DatasetRunOptions::short_sigma_scale
  for (std::size_t k = 0; k < more.run.frames.size(); ++k)
    for (const auto& ob : more.run.frames[k].observations) {
      const bool is_short = (ob.track_id % 3 == 1 && ob.track_id <= max_id) ||
                            (ob.track_id == longest && k >= 30 && k < 40) ||
                            (ob.track_id == second && (k == 50 || k == 51));
      if (is_short) ++doubled;
      EXPECT_DOUBLE_EQ(ob.sigma_scale, is_short ? want_more.short_sigma_scale : 1.0)
          << "frame " << k << " track " << ob.track_id;
    }
  EXPECT_GT(doubled, 0);
  ASSERT_FALSE(more.warnings.empty());
  EXPECT_NE(more.warnings.back().find("lines at least 0.25 of it are used"), std::string::npos)
      << more.warnings.back();
  want_more.enough_tracks = sel.tracks;  // enough at 0.5: no change, no warning
  const pipeline::DatasetRun enough = pipeline::calibration_run_from_tracks(d, mixed, want_more);
  EXPECT_DOUBLE_EQ(enough.min_annulus_fraction, 0.5);
  EXPECT_EQ(enough.observations, sel.observations);
  EXPECT_EQ(enough.warnings.size(), sel.warnings.size());
}

TEST_F(SimulatorTest, WheelTravelIntegratesToTheGroundTruthPoses) {
  SimConfig cfg;
  cfg.wheel.odometry_k = 0.0;  // ground-truth wheel travel
  cfg.camera.width = 320;      // small images: this test is about odometry
  cfg.camera.height = 240;
  cfg.camera.cx = 160.3;
  cfg.camera.cy = 119.6;
  cfg.camera.gamma = 60;
  cfg.camera.r_min = 28;
  cfg.camera.r_max = 105;
  const std::string out = (dir / "paper").string();
  const SimSummary s = simulate(world_preset("corridor"), load_trajectory("paper"), cfg, out);
  EXPECT_EQ(s.frames, 93);
  EXPECT_NEAR(s.distance, 2.3, 0.04);

  const dataset::Dataset d = dataset::Dataset::load(out);
  ASSERT_TRUE(d.ground_truth().has_value());
  const auto& gt = *d.ground_truth();
  ASSERT_EQ(gt.poses.size(), d.size());
  ASSERT_TRUE(gt.extrinsics.has_value());
  EXPECT_DOUBLE_EQ(gt.extrinsics->phi, -0.34);
  EXPECT_DOUBLE_EQ(gt.extrinsics->rho, 0.23);
  EXPECT_DOUBLE_EQ(gt.extrinsics->psi, 0.33);
  const double e = d.wheel_sensor().wheel_base;

  // Eq. (14)-(15) over the 50 Hz wheel samples, starting at the first image's pose with the
  // travel interpolated at its timestamp.
  const auto& wheel = d.wheel();
  double x = gt.poses[0].x, y = gt.poses[0].y, th = gt.poses[0].theta;
  dataset::WheelTravel prev = d.travel_at_images()[0];
  std::size_t w = 0;
  while (wheel[w].timestamp_ns <= d.images()[0].timestamp_ns) ++w;
  double max_pos = 0, max_th = 0;
  auto step = [&](const dataset::WheelTravel& now) {
    const double dl = now.left - prev.left, dr = now.right - prev.right;
    const double drho = 0.5 * (dr + dl), dth = (dr - dl) / e;  // eq. (15)
    x += drho * std::cos(th + 0.5 * dth);                      // eq. (14)
    y += drho * std::sin(th + 0.5 * dth);
    th += dth;
    prev = now;
  };
  for (std::size_t i = 1; i < d.size(); ++i) {
    const std::int64_t t = d.images()[i].timestamp_ns;
    while (wheel[w].timestamp_ns < t) step(wheel[w++].travel);
    step(d.travel_at_images()[i]);
    max_pos = std::max(max_pos, std::hypot(x - gt.poses[i].x, y - gt.poses[i].y));
    max_th = std::max(max_th, std::abs(angle_diff(th, gt.poses[i].theta)));
  }
  std::printf("odometry vs ground truth over %zu frames: max %.2e m, %.2e rad\n",
              d.size(),
              max_pos,
              max_th);
  EXPECT_LT(max_pos, 1e-4);
  EXPECT_LT(max_th, 1e-5);
  EXPECT_NEAR(std::abs(gt.poses.back().theta), kPi, 1e-6);  // the paper's 180 degree turn

  expect_lines_follow_edges(fs::path(out), gt, cfg);

  // What the calibration sees (pipeline::calibration_run_from_tracks, the ground truth's lines as
  // tracks): one step per frame, composed from the wheel samples between the images, with its
  // sideways displacement (FrameInput::lateral). Dead-reckoned, it gives the ground-truth
  // poses; eq. (14) once per frame does not (frame 61 ends the straight and starts the turn).
  std::vector<TrackRow> rows;
  for (const auto& l : gt.lines) {
    TrackRow r;
    r.frame = l.frame;
    r.timestamp_ns = d.images()[static_cast<std::size_t>(l.frame)].timestamp_ns;
    r.track_id = l.line_id;
    r.bearing = r.image_angle = l.bearing;
    rows.push_back(r);
  }
  const pipeline::DatasetRun run = pipeline::calibration_run_from_tracks(d, rows);
  const std::vector<Eigen::Vector3d> dr = calib::dead_reckoning(run.run, e);
  calib::CalibrationRun one_step = run.run;
  for (calib::FrameInput& f : one_step.frames) f.lateral = 0.0;
  const std::vector<Eigen::Vector3d> dr1 = calib::dead_reckoning(one_step, e);
  double max_run = 0, max_one = 0, max_lateral = 0;
  const auto& g0 = gt.poses[0];
  for (std::size_t i = 0; i < d.size(); ++i) {
    // The ground truth in the robot frame of the first image.
    const double dx = gt.poses[i].x - g0.x, dy = gt.poses[i].y - g0.y;
    const Eigen::Vector2d g(std::cos(g0.theta) * dx + std::sin(g0.theta) * dy,
                            -std::sin(g0.theta) * dx + std::cos(g0.theta) * dy);
    max_run = std::max(max_run, (dr[i].head<2>() - g).norm());
    max_one = std::max(max_one, (dr1[i].head<2>() - g).norm());
    max_lateral = std::max(max_lateral, std::abs(run.run.frames[i].lateral));
  }
  std::printf(
      "dead reckoning of the calibration's frames: max %.2e m (eq. 14 once per frame: "
      "%.2e m; largest sideways step %.2e m)\n",
      max_run,
      max_one,
      max_lateral);
  EXPECT_LT(max_run, 1e-5);
  EXPECT_GT(max_one, 4e-4);
  EXPECT_NEAR(max_lateral, 4.75e-4, 1e-5);

  expect_short_lines_left_out(d, rows, run);
}

TEST(Presets, EveryTrajectoryPresetFitsEveryWorldPreset) {
  for (const std::string& wn : world_presets()) {
    const World w = world_preset(wn);
    for (const std::string& tn : trajectory_presets()) {
      const auto motion = load_trajectory(tn).pieces(w.start);
      EXPECT_EQ(free_space_violation(w, motion, duration(motion), 0.25), "") << wn << " " << tn;
    }
  }
}

TEST(Presets, RandomWorldsFitEveryTrajectoryAndDiffer) {
  // 20 seeds x every trajectory: the room keeps the path clear (0.25 m from every wall and
  // piece of furniture), validates, has vertical edges to see; the same seed is the same
  // world, another seed another.
  for (const std::string& tn : trajectory_presets()) {
    const auto motion = load_trajectory(tn).pieces(Pose2::Zero());
    std::vector<Eigen::Vector2d> path;
    for (double t = 0.0; t <= duration(motion) + 0.05; t += 0.05)
      path.push_back(pose_at(motion, t).head<2>());
    std::set<std::size_t> edge_counts;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const World w = random_world(seed, path);
      EXPECT_EQ(w.validate(), "") << tn << " seed " << seed;
      EXPECT_EQ(free_space_violation(w, motion, duration(motion), 0.25), "")
          << tn << " seed " << seed;
      EXPECT_GE(w.edges().size(), 20u) << tn << " seed " << seed;
      EXPECT_EQ(random_world(seed, path).edges().size(), w.edges().size());
      edge_counts.insert(w.edges().size());
    }
    EXPECT_GE(edge_counts.size(), 10u) << tn;
  }
}

TEST_F(SimulatorTest, SameSeedSameDataDifferentSeedDifferentNoise) {
  SimConfig cfg;
  cfg.max_frames = 3;
  const World w = world_preset("office");
  const Trajectory t = load_trajectory("zigzag");
  simulate(w, t, cfg, (dir / "a").string());
  simulate(w, t, cfg, (dir / "b").string());
  cfg.seed = 2;
  simulate(w, t, cfg, (dir / "c").string());
  const fs::path img = fs::path("cam0") / "data" / "1600000000343333333.png";
  EXPECT_EQ(slurp(dir / "a" / img), slurp(dir / "b" / img));
  EXPECT_EQ(slurp(dir / "a" / "wheel0" / "data.csv"), slurp(dir / "b" / "wheel0" / "data.csv"));
  EXPECT_NE(slurp(dir / "a" / img), slurp(dir / "c" / img));
  EXPECT_NE(slurp(dir / "a" / "wheel0" / "data.csv"), slurp(dir / "c" / "wheel0" / "data.csv"));
  EXPECT_EQ(slurp(dir / "a" / "ground_truth" / "lines.csv"),
            slurp(dir / "c" / "ground_truth" / "lines.csv"));
}

TEST_F(SimulatorTest, FailedRunLeavesNoDatasetAndExistingOutputIsKept) {
  SimConfig cfg;
  Trajectory t;
  t.name = "into-the-wall";
  t.segments = {{Segment::Kind::kStraight, 0.5, 0, 0},
                {Segment::Kind::kTurn, 0, kPi / 2, 0},
                {Segment::Kind::kStraight, 3.0, 0, 0}};
  const std::string out = (dir / "bad").string();
  try {
    simulate(world_preset("corridor"), t, cfg, out);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("trajectory 'into-the-wall' leaves the free space"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(dir))
    ADD_FAILURE() << "left behind: " << entry.path();

  cfg.max_frames = 1;
  const std::string ok = (dir / "ok").string();
  simulate(world_preset("corridor"), load_trajectory("straight"), cfg, ok);
  try {
    simulate(world_preset("corridor"), load_trajectory("straight"), cfg, ok);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), ok + ": already exists (use --force to replace it)");
  }
  EXPECT_NO_THROW(simulate(world_preset("corridor"), load_trajectory("straight"), cfg, ok, true));
}

TEST_F(SimulatorTest, WrappingTickCountersReadBackAsMeters) {
  SimConfig cfg;
  cfg.max_frames = 40;
  cfg.wheel.ticks = true;
  cfg.wheel.ticks_per_meter_left = 20000;
  cfg.wheel.ticks_per_meter_right = 19000;
  cfg.wheel.counter_bits = 12;  // wraps every ~0.2 m
  cfg.wheel.odometry_k = 0;
  cfg.camera.width = 160;
  cfg.camera.height = 120;
  cfg.camera.cx = 80.2;
  cfg.camera.cy = 60.1;
  cfg.camera.gamma = 30;
  cfg.camera.r_min = 14;
  cfg.camera.r_max = 50;
  const std::string out = (dir / "ticks").string();
  simulate(world_preset("hall"), load_trajectory("paper"), cfg, out);
  const dataset::Dataset d = dataset::Dataset::load(out);
  ASSERT_EQ(d.wheel_sensor().unit, dataset::WheelUnit::kTicks);
  // 40 frames at 3.8 cm: about 1.5 m, several wraps of the 12-bit counters.
  const auto& last = d.wheel().back().travel;
  EXPECT_GT(last.left, 1.4);
  const double expected =
      (d.wheel().back().timestamp_ns - d.wheel().front().timestamp_ns) * 1e-9 * 0.114;
  EXPECT_NEAR(last.left, expected, 1.0 / 20000 + 1e-9);
  EXPECT_NEAR(last.right, expected, 1.0 / 19000 + 1e-9);
}

}  // namespace
}  // namespace omnivert::sim
