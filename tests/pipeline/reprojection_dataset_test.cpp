// The check by eye on a simulated dataset with a laser scanner (laser0/): the scans read back,
// the corners meeting the extracted lines with the true mounting and missing them with the
// paper's hand measurement, and bad laser data (NaN and inf ranges, a scanner pose missing,
// scans that do not overlap the images) refused or counted with a clear message.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/dataset/laser.hpp"
#include "omnivert/pipeline/reprojection.hpp"
#include "omnivert/sim/simulator.hpp"
#include "simulated_datasets.hpp"

namespace omnivert::pipeline {
namespace {

namespace fs = std::filesystem;
using testing::read_lines;
using testing::read_text;
using testing::write_text;

class ReprojectionDataset : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("omnivert_reprojection_" + std::to_string(::getpid())));
    sim::SimConfig cfg;
    cfg.max_frames = 8;
    cfg.laser.enabled = true;
    // Noise-free wheels: dead reckoning is then exact (with the default K = 1e-5 m the heading
    // drifts by about 0.4 degree over these 8 frames, and so do corners carried by it).
    cfg.wheel.odometry_k = 0.0;
    sim::simulate(sim::load_world("corridor"),
                  sim::load_trajectory("paper"),
                  cfg,
                  (*dir_ / "run").string(),
                  true);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
  }
  // A copy of the dataset to damage.
  static fs::path copy(const std::string& name) {
    const fs::path to = *dir_ / name;
    fs::remove_all(to);
    fs::copy(*dir_ / "run", to, fs::copy_options::recursive);
    return to;
  }
  static dataset::Dataset load(const fs::path& d) { return dataset::Dataset::load(d.string()); }
  static std::string error_of(const std::function<void()>& f) {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  static fs::path* dir_;
};
fs::path* ReprojectionDataset::dir_ = nullptr;

TEST_F(ReprojectionDataset, ScansReadBackWithTheScannerPose) {
  const auto laser = dataset::load_laser((*dir_ / "run").string());
  ASSERT_TRUE(laser.has_value());
  const sim::LaserConfig c;
  EXPECT_DOUBLE_EQ(laser->sensor.x, c.x);
  EXPECT_DOUBLE_EQ(laser->sensor.z, c.height);
  ASSERT_FALSE(laser->scans.empty());
  EXPECT_EQ(laser->scans.front().ranges.size(), static_cast<std::size_t>(c.rays));
  // 8 frames at 3 Hz from 10 ms: 2.343 s; scans every 0.1 s from 0 up to and past it.
  EXPECT_EQ(laser->scans.size(), 25u);
  EXPECT_EQ(laser->scans[1].timestamp_ns - laser->scans[0].timestamp_ns, 100'000'000);
}

TEST_F(ReprojectionDataset, TrueMountingMeetsTheLinesThePriorMissesThem) {
  const auto data = load(*dir_ / "run");
  ReprojectionOptions o;
  const References refs = load_references(data, o.reference);
  EXPECT_EQ(refs.frames.size(), data.size());
  const calib::Extrinsics prior{0.0, 0.2, 0.0}, truth{-0.34, 0.23, 0.33};
  const auto r = check_reprojection(data, refs, {}, prior, truth, o);
  // The first 8 frames of the paper's run: the prior's camera is 8 cm from the true one.
  EXPECT_GE(r.stats_after.matched, 8) << r.message();
  EXPECT_GT(r.stats_after.matched, r.stats_before.matched) << r.message();
  EXPECT_LT(rad2deg(r.stats_after.median_abs), 0.1) << r.message();
  EXPECT_GT(r.stats_before.median_abs, 3 * r.stats_after.median_abs) << r.message();
  EXPECT_EQ(r.picture.cols, 2 * data.camera().width);
  EXPECT_EQ(r.picture.rows, data.camera().height);
}

TEST_F(ReprojectionDataset, MapCornersMeetTheLinesWithTheTrueMounting) {
  const auto data = load(*dir_ / "run");
  ReprojectionOptions o;
  o.reference.source = ReferenceSource::kMap;
  const auto r = check_reprojection(data,
                                    load_references(data, o.reference),
                                    {},
                                    calib::Extrinsics{},
                                    calib::Extrinsics{-0.34, 0.23, 0.33},
                                    o);
  EXPECT_GT(r.stats_after.matched, 40) << r.message();
  EXPECT_LT(rad2deg(r.stats_after.median_abs), 0.05) << r.message();
  EXPECT_GT(rad2deg(r.stats_before.median_abs), 0.3) << r.message();
}

TEST_F(ReprojectionDataset, KnownCornersCarriedByDeadReckoning) {
  // The map's edges visible in the first frame over half the annulus, written as a user's
  // corners file in the robot frame of the first image.
  const auto data = load(*dir_ / "run");
  const auto& gt = *data.ground_truth();
  const Pose2d start(gt.poses[0].x, gt.poses[0].y, gt.poses[0].theta);
  const auto edges =
      dataset::load_edges_csv((*dir_ / "run" / "ground_truth" / "edges.csv").string());
  const double half = 0.5 * (*data.camera().r_max - *data.camera().r_min);
  std::string csv = "#x [m],y [m]\n";
  int n = 0;
  for (const auto& l : gt.lines_in_frame(0))
    if (l.r_outer - l.r_inner >= half)
      for (const auto& e : edges)
        if (e.id == l.line_id) {
          const Eigen::Vector2d p = transform_point(inverse(start), e.p);
          csv += std::to_string(p.x()) + "," + std::to_string(p.y()) + "\n";
          ++n;
        }
  ASSERT_GT(n, 5);
  write_text(*dir_ / "corners.csv", csv);
  ReprojectionOptions o;
  o.reference.source = ReferenceSource::kCorners;
  o.reference.corners_file = (*dir_ / "corners.csv").string();
  const auto r = check_reprojection(data,
                                    load_references(data, o.reference),
                                    {},
                                    calib::Extrinsics{},
                                    calib::Extrinsics{-0.34, 0.23, 0.33},
                                    o);
  EXPECT_GT(r.stats_after.matched, 2 * n) << r.message();
  EXPECT_LT(rad2deg(r.stats_after.median_abs), 0.05) << r.message();
  EXPECT_GT(rad2deg(r.stats_before.median_abs), 0.3) << r.message();
  write_text(*dir_ / "bad-corners.csv", "#x [m],y [m]\n1.0,one\n");
  o.reference.corners_file = (*dir_ / "bad-corners.csv").string();
  EXPECT_EQ(error_of([&] { load_references(data, o.reference); }),
            (*dir_ / "bad-corners.csv").string() + ":2: cannot parse y 'one' as a finite number");
}

TEST_F(ReprojectionDataset, NanAndInfRangesAreNoReturnsAndCounted) {
  const auto base = dataset::load_laser((*dir_ / "run").string());
  ASSERT_TRUE(base.has_value());
  const fs::path d = copy("nan");
  auto lines = read_lines(d / "laser0" / "data.csv");
  // Row 1 (file line 2): the first two finite ranges become nan and inf.
  std::vector<std::string> f;
  for (std::size_t at = 0;;) {
    const std::size_t comma = lines[1].find(',', at);
    f.push_back(lines[1].substr(at, comma - at));
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  int replaced = 0;
  for (std::size_t k = 5; k < f.size() && replaced < 2; ++k)
    if (f[k] != "inf" && f[k] != "-inf") f[k] = replaced++ == 0 ? "nan" : "inf";
  lines[1] = f[0];
  for (std::size_t k = 1; k < f.size(); ++k) lines[1] += "," + f[k];
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  write_text(d / "laser0" / "data.csv", text);
  const auto laser = dataset::load_laser(d.string());
  ASSERT_TRUE(laser.has_value());
  EXPECT_EQ(laser->non_finite, base->non_finite + 2);
  EXPECT_EQ(laser->no_returns, base->no_returns + 2);
  EXPECT_TRUE(std::isnan(
      laser->scans[0].ranges[5 - 5 +
                             static_cast<std::size_t>(std::find(f.begin() + 5, f.end(), "nan") -
                                                      f.begin() - 5)]));
  EXPECT_NE(laser->describe().find(std::to_string(base->non_finite + 2) + " not finite"),
            std::string::npos)
      << laser->describe();
  EXPECT_NO_THROW(load_references(load(d), ReferenceOptions{}));
}

TEST_F(ReprojectionDataset, ScansWithOnlyNanAreRefused) {
  const fs::path d = copy("all_nan");
  const auto lines = read_lines(d / "laser0" / "data.csv");
  std::string text = lines[0] + "\n";
  for (std::size_t i = 1; i < lines.size(); ++i)
    text += lines[i].substr(0, lines[i].find(',')) + ",-3.14,0.1,0.05,8,nan,nan,inf,-inf\n";
  write_text(d / "laser0" / "data.csv", text);
  EXPECT_EQ(error_of([&] { dataset::load_laser(d.string()); }),
            (d / "laser0" / "data.csv").string() +
                ": no scan has a usable range: all 100 ranges are nan, inf or outside "
                "range_min..range_max");
}

TEST_F(ReprojectionDataset, BadRangeNamesLineAndColumn) {
  const fs::path d = copy("bad_range");
  auto lines = read_lines(d / "laser0" / "data.csv");
  lines[3] += ",abc";
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  write_text(d / "laser0" / "data.csv", text);
  EXPECT_EQ(error_of([&] { dataset::load_laser(d.string()); }),
            (d / "laser0" / "data.csv").string() +
                ":4: cannot parse range 1440 (column 1446) 'abc' as a number (or nan, inf)");
}

TEST_F(ReprojectionDataset, ScannerPoseMissing) {
  const fs::path d = copy("no_pose");
  fs::remove(d / "laser0" / "sensor.yaml");
  EXPECT_EQ(error_of([&] { dataset::load_laser(d.string()); }),
            (d / "laser0" / "sensor.yaml").string() + ": file not found");
  write_text(d / "laser0" / "sensor.yaml", "x: 0.1\ny: 0\n");
  EXPECT_EQ(error_of([&] { dataset::load_laser(d.string()); }),
            (d / "laser0" / "sensor.yaml").string() + ": missing required field 'yaw'");
}

TEST_F(ReprojectionDataset, ScansOutsideTheImagesTimeAreRefused) {
  const fs::path d = copy("late");
  const auto lines = read_lines(d / "laser0" / "data.csv");
  std::string text = lines[0] + "\n";
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::size_t comma = lines[i].find(',');
    text += std::to_string(std::stoll(lines[i].substr(0, comma)) + 1'000'000'000'000LL) +
            lines[i].substr(comma) + "\n";
  }
  write_text(d / "laser0" / "data.csv", text);
  const std::string e = error_of([&] { load_references(load(d), ReferenceOptions{}); });
  EXPECT_NE(e.find(d.string() + "/laser0/data.csv: the scans (1600001000000000000 to "),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("do not overlap the images (1600000000010000000 to 1600000002343333331 ns) "
                   "inside the wheel data: no image has a scan within 0.1 s"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace omnivert::pipeline
