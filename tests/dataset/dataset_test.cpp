// The dataset reader: every input problem gives an InputError with the file, the line and
// the problem (the exact message is checked), and good data reads back with the right numbers.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"

namespace omnivert::dataset {
namespace {

namespace fs = std::filesystem;

// A tiny valid dataset: three 64x48 images at t = 1000, 2000, 3000 ns (in ms units times 1e6),
// wheel samples every 500 (ms) from 500 to 3500.
class DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root = fs::temp_directory_path() / ("omnivert_ds_" + std::to_string(::getpid()));
    fs::remove_all(root);
    fs::create_directories(root / "cam0" / "data");
    fs::create_directories(root / "wheel0");
    write("cam0/sensor.yaml",
          "resolution: [64, 48]\ncenter: [32.5, 24.5]\nr_min: 5\nr_max: 20\nbearing_sign: 1\n");
    write("cam0/data.csv",
          "#timestamp [ns],filename\n1000000000,a.png\n2000000000,b.png\n3000000000,c.png\n");
    for (const char* f : {"a.png", "b.png", "c.png"})
      image(std::string("cam0/data/") + f, 64, 48, CV_8UC1);
    write("wheel0/sensor.yaml", "wheel_base: 0.4\nunit: meters\nodometry_k: 1.0e-5\n");
    write("wheel0/data.csv",
          "#timestamp [ns],left [m],right [m]\n"
          "500000000,1.0,2.0\n1000000000,1.1,2.0\n1500000000,1.2,2.0\n2000000000,1.3,2.1\n"
          "2500000000,1.4,2.2\n3000000000,1.5,2.3\n3500000000,1.6,2.4\n");
  }
  void TearDown() override { fs::remove_all(root); }

  void write(const std::string& rel, const std::string& text) { std::ofstream(root / rel) << text; }
  void image(const std::string& rel, int w, int h, int type) {
    cv::Mat m(h, w, type, cv::Scalar::all(100));
    ASSERT_TRUE(cv::imwrite((root / rel).string(), m));
  }
  std::string p(const std::string& rel) const { return (root / rel).string(); }
  // The message of the InputError that loading throws.
  std::string error(const LoadOptions& o = {}) {
    try {
      Dataset::load(root.string(), o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path root;
};

TEST_F(DatasetTest, ValidDatasetLoadsWithInterpolatedWheelTravel) {
  const Dataset d = Dataset::load(root.string());
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d.images()[1].timestamp_ns, 2000000000);
  EXPECT_EQ(d.camera().width, 64);
  EXPECT_DOUBLE_EQ(d.wheel_sensor().wheel_base, 0.4);
  ASSERT_TRUE(d.wheel_sensor().odometry_k.has_value());
  // Travel is relative to the first wheel sample.
  const auto& t = d.travel_at_images();
  EXPECT_NEAR(t[0].left, 0.1, 1e-12);
  EXPECT_NEAR(t[1].right, 0.1, 1e-12);
  EXPECT_NEAR(t[2].left, 0.5, 1e-12);
  const WheelTravel mid = d.travel_at(1750000000);  // halfway between 1.2/2.0 and 1.3/2.1
  EXPECT_NEAR(mid.left, 0.25, 1e-12);
  EXPECT_NEAR(mid.right, 0.05, 1e-12);
  EXPECT_EQ(d.image(2).cols, 64);
  EXPECT_FALSE(d.ground_truth().has_value());
}

TEST_F(DatasetTest, MissingDirectoryAndFiles) {
  EXPECT_EQ(error(), "(no error)");
  fs::remove(root / "cam0" / "data.csv");
  EXPECT_EQ(error(), p("cam0/data.csv") + ": file not found");
  fs::remove_all(root);
  EXPECT_EQ(error(), root.string() + ": dataset directory not found");
}

TEST_F(DatasetTest, MissingWheelSensorFile) {
  fs::remove(root / "wheel0" / "sensor.yaml");
  EXPECT_EQ(error(), p("wheel0/sensor.yaml") + ": file not found");
}

TEST_F(DatasetTest, MissingImageFile) {
  fs::remove(root / "cam0" / "data" / "b.png");
  EXPECT_EQ(error(), p("cam0/data.csv") + ":3: image file 'b.png' not found in cam0/data/");
}

TEST_F(DatasetTest, UnparsableTimestamp) {
  write("cam0/data.csv", "#timestamp [ns],filename\n1000000000,a.png\n2000x00000,b.png\n");
  EXPECT_EQ(error(),
            p("cam0/data.csv") +
                ":3: cannot parse timestamp '2000x00000' (expected a non-negative integer in ns)");
}

TEST_F(DatasetTest, TooFewColumnsIsAnError) {
  write("cam0/data.csv", "#timestamp [ns],filename\n1000000000\n");
  EXPECT_EQ(error(),
            p("cam0/data.csv") +
                ":2: expected 2 comma-separated columns (timestamp [ns], filename), got 1");
}

TEST_F(DatasetTest, ExtraTrailingColumnsAreIgnoredWithANote) {
  // Another tool's columns after ours, as EuRoC-style readers accept them.
  write("cam0/data.csv",
        "#timestamp [ns],filename,exposure\n1000000000,a.png,0.01\n2000000000,b.png,0.02\n"
        "3000000000,c.png\n");
  write("wheel0/data.csv",
        "#timestamp [ns],left [m],right [m],temperature\n500000000,1.0,2.0,20\n"
        "1000000000,1.1,2.1,20\n1500000000,1.2,2.2\n2000000000,1.3,2.3\n"
        "2500000000,1.4,2.2\n3000000000,1.5,2.3\n3500000000,1.6,2.4\n");
  const Dataset d = Dataset::load(root.string());
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d.images()[1].filename, "b.png");
  EXPECT_EQ(d.images()[1].timestamp_ns, 2000000000);
  EXPECT_NEAR(d.travel_at(1000000000).left, 0.1, 1e-12);  // travel from the first sample
  ASSERT_EQ(d.notes().size(), 2u);
  EXPECT_EQ(d.notes()[0],
            p("cam0/data.csv") + ": 2 rows have columns beyond the 2 read; those were ignored");
  EXPECT_EQ(d.notes()[1],
            p("wheel0/data.csv") + ": 2 rows have columns beyond the 3 read; those were ignored");
}

TEST_F(DatasetTest, MissingHeader) {
  write("cam0/data.csv", "1000000000,a.png\n");
  EXPECT_EQ(error(),
            p("cam0/data.csv") +
                ":1: expected a header line starting with '#' (timestamp [ns], filename)");
}

TEST_F(DatasetTest, UnparsableWheelValue) {
  write("wheel0/data.csv",
        "#timestamp [ns],left [m],right [m]\n500000000,1.0,2.0\n1000000000,1.1,nan\n");
  EXPECT_EQ(error(),
            p("wheel0/data.csv") + ":3: cannot parse right wheel value 'nan' as a finite number");
}

TEST_F(DatasetTest, DuplicateImageTimestamp) {
  write("cam0/data.csv", "#timestamp [ns],filename\n1000000000,a.png\n1000000000,b.png\n");
  EXPECT_EQ(error(), p("cam0/data.csv") + ":3: duplicate timestamp 1000000000 (also on line 2)");
}

TEST_F(DatasetTest, DecreasingWheelTimestamp) {
  write("wheel0/data.csv",
        "#timestamp [ns],left [m],right "
        "[m]\n500000000,1.0,2.0\n\n1500000000,1.1,2.0\n1000000000,1.2,2.0\n");
  EXPECT_EQ(error(),
            p("wheel0/data.csv") +
                ":5: timestamp 1000000000 is earlier than 1500000000 on line 4: timestamps must "
                "increase");
}

TEST_F(DatasetTest, ImageOfTheWrongSize) {
  image("cam0/data/a.png", 32, 24, CV_8UC1);
  EXPECT_EQ(
      error(),
      p("cam0/data/a.png") + ": image is 32x24 pixels but cam0/sensor.yaml gives resolution 64x48");
}

TEST_F(DatasetTest, SixteenBitImagesAreScaledToEightBits) {
  cv::Mat1w m(48, 64, static_cast<uint16_t>(100 * 257));
  m(10, 20) = 65535;
  ASSERT_TRUE(cv::imwrite(p("cam0/data/a.png"), m));
  const Dataset d = Dataset::load(root.string());
  const cv::Mat1b g = d.image(0);
  EXPECT_EQ(g(0, 0), 100);
  EXPECT_EQ(g(10, 20), 255);
}

TEST_F(DatasetTest, TwelveBitImagesUseTheSensorsBitDepth) {
  write("cam0/sensor.yaml", "resolution: [64, 48]\nbit_depth: 12\n");
  cv::Mat1w m(48, 64, static_cast<uint16_t>(4095));
  m(0, 0) = 0;
  ASSERT_TRUE(cv::imwrite(p("cam0/data/a.png"), m));
  const cv::Mat1b g = Dataset::load(root.string()).image(0);
  EXPECT_EQ(g(0, 0), 0);
  EXPECT_EQ(g(1, 1), 255);
}

TEST_F(DatasetTest, BayerPatternOnAColourImageIsRefused) {
  write("cam0/sensor.yaml", "resolution: [64, 48]\nbayer: RGGB\n");
  image("cam0/data/a.png", 64, 48, CV_8UC3);
  EXPECT_EQ(error(),
            p("cam0/data/a.png") +
                ": the camera's images are Bayer mosaics (bayer: RGGB) but this image has 3 "
                "channels; set bayer: none in sensor.yaml for colour images");
}

TEST_F(DatasetTest, UnknownBayerPatternNamesTheLine) {
  write("cam0/sensor.yaml", "resolution: [64, 48]\nbayer: RGBG\n");
  EXPECT_EQ(error(),
            p("cam0/sensor.yaml") +
                ":2: field 'bayer' is 'RGBG'; expected RGGB, BGGR, GRBG, GBRG or none");
}

TEST_F(DatasetTest, BitDepthOutOfRangeNamesTheLine) {
  write("cam0/sensor.yaml", "resolution: [64, 48]\nbit_depth: 8\n");
  EXPECT_EQ(error(),
            p("cam0/sensor.yaml") +
                ":2: field 'bit_depth' must be a whole number of bits from 9 to 16 (the "
                "significant bits of a 16-bit image)");
}

TEST_F(DatasetTest, BadImageLaterInTheSequenceIsFoundWhenRead) {
  image("cam0/data/c.png", 64, 40, CV_8UC1);
  const Dataset d = Dataset::load(root.string());  // only the first image is read on load
  try {
    (void)d.image(2);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              p("cam0/data/c.png") +
                  ": image is 64x40 pixels but cam0/sensor.yaml gives resolution 64x48");
  }
  LoadOptions all;
  all.check_all_images = true;
  EXPECT_EQ(
      error(all),
      p("cam0/data/c.png") + ": image is 64x40 pixels but cam0/sensor.yaml gives resolution 64x48");
}

TEST_F(DatasetTest, FileThatIsNotAnImage) {
  write("cam0/data/a.png", "not a png");
  EXPECT_EQ(error(), p("cam0/data/a.png") + ": cannot be read as an image");
}

TEST_F(DatasetTest, WindowsLineEndingsAndSpacesAreAccepted) {
  write("cam0/data.csv",
        "#timestamp [ns],filename\r\n1000000000, a.png\r\n2000000000 ,b.png\r\n\r\n");
  const Dataset d = Dataset::load(root.string());
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.images()[0].filename, "a.png");
  EXPECT_EQ(d.images()[1].timestamp_ns, 2000000000);
}

TEST_F(DatasetTest, ColourImageIsConvertedToGrey) {
  image("cam0/data/a.png", 64, 48, CV_8UC3);
  const Dataset d = Dataset::load(root.string());
  EXPECT_EQ(d.image(0).channels(), 1);
}

TEST_F(DatasetTest, WheelDataNotCoveringTheImages) {
  write("wheel0/data.csv",
        "#timestamp [ns],left [m],right [m]\n500000000,1.0,2.0\n2500000000,1.1,2.0\n");
  EXPECT_EQ(error(),
            p("wheel0/data.csv") +
                ": wheel data (timestamps 500000000 to 2500000000) does not cover the image at "
                "line 4 of cam0/data.csv (timestamp 3000000000)");
}

TEST_F(DatasetTest, WheelsAreOptionalOnlyWhenAllowed) {
  fs::remove_all(root / "wheel0");
  EXPECT_EQ(error(), p("wheel0/sensor.yaml") + ": file not found");
  LoadOptions o;
  o.require_wheel = false;
  const Dataset d = Dataset::load(root.string(), o);
  EXPECT_FALSE(d.has_wheel());
}

TEST_F(DatasetTest, WheelSensorFields) {
  write("wheel0/sensor.yaml", "unit: meters\n");
  EXPECT_EQ(error(), p("wheel0/sensor.yaml") + ": missing required field 'wheel_base'");
  write("wheel0/sensor.yaml", "wheel_base: 0.4\nunit: furlongs\n");
  EXPECT_EQ(error(),
            p("wheel0/sensor.yaml") + ":2: field 'unit' must be meters or ticks, got 'furlongs'");
  write("wheel0/sensor.yaml", "wheel_base: 0.4\nunit: ticks\nticks_per_meter_left: 100\n");
  EXPECT_EQ(error(), p("wheel0/sensor.yaml") + ": missing required field 'ticks_per_meter_right'");
  write("wheel0/sensor.yaml", "wheel_base: 0.4\nunit: meters\ncounter_bits: 16\n");
  EXPECT_EQ(error(), p("wheel0/sensor.yaml") + ":3: field 'counter_bits' needs 'unit: ticks'");
}

TEST_F(DatasetTest, HeaderUnitMustMatchTheSensorUnit) {
  write("wheel0/sensor.yaml",
        "wheel_base: 0.4\nunit: ticks\nticks_per_meter_left: 1000\nticks_per_meter_right: 1000\n");
  EXPECT_EQ(error(),
            p("wheel0/data.csv") + ":1: header says [m] but wheel0/sensor.yaml says 'unit: ticks'");
}

class TicksTest : public DatasetTest {
 protected:
  void SetUp() override {
    DatasetTest::SetUp();
    // 8-bit counters at 1000 ticks/m: +100 ticks (0.1 m) per 0.5 s, wrapping at 256.
    write("wheel0/data.csv",
          "#timestamp [ns],left [ticks],right [ticks]\n"
          "500000000,200,10\n1000000000,44,110\n1500000000,144,210\n2000000000,244,54\n"
          "2500000000,88,154\n3000000000,188,254\n3500000000,32,98\n");
  }
  void sensor(const std::string& extra) {
    write(
        "wheel0/sensor.yaml",
        "wheel_base: 0.4\nunit: ticks\nticks_per_meter_left: 1000\nticks_per_meter_right: 1000\n" +
            extra);
  }
};

TEST_F(TicksTest, WrappedCountersAreUnwrappedWithCounterBits) {
  sensor("counter_bits: 8\n");
  const Dataset d = Dataset::load(root.string());
  EXPECT_NEAR(d.wheel().back().travel.left, 0.6, 1e-12);
  EXPECT_NEAR(d.wheel().back().travel.right, 0.6, 1e-12);
  EXPECT_NEAR(d.travel_at_images()[2].left, 0.5, 1e-12);
}

TEST_F(TicksTest, WrappedCounterWithoutCounterBitsIsAnImplausibleJump) {
  sensor("");
  LoadOptions o;
  o.max_wheel_speed = 0.3;
  EXPECT_EQ(error(o),
            p("wheel0/data.csv") +
                ":3: left wheel jumps by -0.156 m in 0.5 s (0.312 m/s, more than the plausible 0.3 "
                "m/s); if the tick counter wraps, give counter_bits in wheel0/sensor.yaml");
}

TEST_F(TicksTest, ImplausibleJumpAfterUnwrapping) {
  sensor("counter_bits: 12\n");  // wrong: the counters wrap at 8 bits
  LoadOptions o;
  o.max_wheel_speed = 0.3;
  try {
    Dataset::load(root.string(), o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              p("wheel0/data.csv") +
                  ":3: left wheel jumps by -0.156 m in 0.5 s (0.312 m/s, more than the "
                  "plausible 0.3 m/s); check counter_bits and ticks_per_meter in "
                  "wheel0/sensor.yaml");
  }
}

TEST_F(DatasetTest, GroundTruthIsReadAndChecked) {
  fs::create_directories(root / "ground_truth");
  write("ground_truth/extrinsics.yaml", "phi: -0.34\nrho: 0.23\npsi: 0.33\n");
  write("ground_truth/poses.csv",
        "#timestamp [ns],x [m],y [m],theta "
        "[rad]\n1000000000,0,0,0\n2000000000,0.1,0,0\n3000000000,0.2,0,0.1\n");
  write("ground_truth/lines.csv",
        "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer [px]\n"
        "1000000000,0,4,0.5,6,19\n2000000000,1,4,0.6,6,19\n");
  {
    const Dataset d = Dataset::load(root.string());
    ASSERT_TRUE(d.ground_truth().has_value());
    const GroundTruth& gt = *d.ground_truth();
    EXPECT_DOUBLE_EQ(gt.extrinsics->rho, 0.23);
    ASSERT_EQ(gt.poses.size(), 3u);
    EXPECT_DOUBLE_EQ(gt.poses[2].theta, 0.1);
    ASSERT_EQ(gt.lines.size(), 2u);
    EXPECT_EQ(gt.lines[1].line_id, 4);
    EXPECT_DOUBLE_EQ(gt.lines[1].bearing, 0.6);
    ASSERT_EQ(gt.lines_in_frame(1).size(), 1u);
    EXPECT_DOUBLE_EQ(gt.lines_in_frame(1)[0].bearing, 0.6);
    EXPECT_TRUE(gt.lines_in_frame(2).empty());
    EXPECT_TRUE(gt.lines_in_frame(3).empty());
  }
  // A ground truth that cannot be read does not refuse the dataset: the tools that need it
  // report the problem (file, line) from ground_truth_error().
  const auto gt_error = [&] {
    const Dataset d = Dataset::load(root.string());
    EXPECT_FALSE(d.ground_truth().has_value());
    return d.ground_truth_error();
  };
  write("ground_truth/lines.csv",
        "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer "
        "[px]\n1000000000,7,4,0.5,6,19\n");
  EXPECT_EQ(gt_error(), p("ground_truth/lines.csv") + ":2: frame 7 is not an image index (0..2)");
  write("ground_truth/lines.csv",
        "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer "
        "[px]\n1000000001,0,4,0.5,6,19\n");
  EXPECT_EQ(gt_error(),
            p("ground_truth/lines.csv") +
                ":2: timestamp 1000000001 is not that of frame 0 in cam0/data.csv");
  write("ground_truth/extrinsics.yaml", "phi: -0.34\nrho: 0.23\n");
  EXPECT_EQ(gt_error(), p("ground_truth/extrinsics.yaml") + ": missing required field 'psi'");
  // Another tool's ground truth, one column more than ours: read, the extra column ignored.
  write("ground_truth/extrinsics.yaml", "phi: -0.34\nrho: 0.23\npsi: 0.33\n");
  write("ground_truth/lines.csv",
        "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer [px],score\n"
        "1000000000,0,4,0.5,6,19,0.9\n");
  const Dataset d = Dataset::load(root.string());
  ASSERT_TRUE(d.ground_truth().has_value());
  EXPECT_TRUE(d.ground_truth_error().empty());
  ASSERT_EQ(d.ground_truth()->lines.size(), 1u);
  EXPECT_DOUBLE_EQ(d.ground_truth()->lines[0].r_outer, 19.0);
  ASSERT_EQ(d.notes().size(), 1u);
}

// LoadOptions::ground_truth_lines = false (calibrate without the map check): lines.csv is not
// read, not even checked; the rest of the ground truth is.
TEST_F(DatasetTest, GroundTruthLinesAreLeftUnreadWhenNotWanted) {
  fs::create_directories(root / "ground_truth");
  write("ground_truth/extrinsics.yaml", "phi: -0.34\nrho: 0.23\npsi: 0.33\n");
  write("ground_truth/lines.csv",
        "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer [px]\n"
        "1000000000,0,4,0.5,6,19\n2000000000,7,4,0.6,6,19\n");
  LoadOptions without;
  without.ground_truth_lines = false;
  const Dataset d = Dataset::load(root.string(), without);
  ASSERT_TRUE(d.ground_truth().has_value()) << d.ground_truth_error();
  EXPECT_DOUBLE_EQ(d.ground_truth()->extrinsics->rho, 0.23);
  EXPECT_FALSE(d.ground_truth()->has_lines);
  EXPECT_TRUE(d.ground_truth()->lines.empty());
  // Read (the default), the same file's frame 7 is refused.
  const Dataset with = Dataset::load(root.string());
  EXPECT_FALSE(with.ground_truth().has_value());
  EXPECT_EQ(with.ground_truth_error(),
            p("ground_truth/lines.csv") + ":3: frame 7 is not an image index (0..2)");
}

TEST_F(DatasetTest, OccluderEdgesAreReadAndChecked) {
  fs::create_directories(root / "ground_truth");
  write("ground_truth/occluders.csv",
        "#timestamp [ns],frame,occluder,bearing [rad]\n1000000000,0,1,0.25\n1000000000,0,1,0.5\n");
  {
    const Dataset d = Dataset::load(root.string());
    ASSERT_TRUE(d.ground_truth().has_value());
    const auto& o = d.ground_truth()->occluders;
    ASSERT_EQ(o.size(), 2u);
    EXPECT_EQ(o[1].frame, 0);
    EXPECT_EQ(o[1].occluder, 1);
    EXPECT_DOUBLE_EQ(o[1].bearing, 0.5);
  }
  write("ground_truth/occluders.csv",
        "#timestamp [ns],frame,occluder,bearing [rad]\n1000000000,9,1,0.25\n");
  {
    const Dataset d = Dataset::load(root.string());
    EXPECT_FALSE(d.ground_truth().has_value());
    EXPECT_EQ(d.ground_truth_error(),
              p("ground_truth/occluders.csv") + ":2: frame 9 is not an image index (0..2)");
  }
  write("ground_truth/occluders.csv",
        "#timestamp [ns],frame,occluder,bearing [rad]\n1000000000,0,1,nan-ish\n");
  const Dataset d = Dataset::load(root.string());
  EXPECT_FALSE(d.ground_truth().has_value());
  EXPECT_NE(d.ground_truth_error().find(p("ground_truth/occluders.csv") + ":2:"),
            std::string::npos);
}

}  // namespace
}  // namespace omnivert::dataset
