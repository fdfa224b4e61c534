// omnivert import through the library: the datasets written from the fixtures read back with
// the fixtures' numbers (pixels, wheel travel), and every kind of bad input gives a message
// naming the recording, the topic and the message, and leaves no dataset behind.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/recording/import.hpp"

namespace omnivert::recording {
namespace {

namespace fs = std::filesystem;
const std::string kFx = OMNIVERT_RECORDING_FIXTURES;

int pixel(int k, int x, int y) { return (x + 2 * y + 10 * k) % 256; }

class ImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_import_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    o.out = (dir / "ds").string();
    o.image_topic = "/camera/image_raw";
  }
  void TearDown() override { fs::remove_all(dir); }
  ImportSummary run(const std::string& fixture) {
    auto rec = open_recording(kFx + "/" + fixture);
    return import_recording(*rec, o);
  }
  // The message of the InputError the import throws; checks that nothing is left in dir.
  std::string error(const std::string& fixture) {
    std::string what = "no error";
    try {
      run(fixture);
    } catch (const InputError& e) {
      what = e.what();
    }
    EXPECT_TRUE(fs::is_empty(dir)) << "a partial dataset was left in " << dir;
    return what;
  }
  void joint_states() {
    o.joint_states_topic = "/joint_states";
    o.left_joint = "wheel_left_joint";
    o.right_joint = "wheel_right_joint";
    o.wheel_radius = 0.1;
    o.wheel_base = 0.5;
  }
  fs::path dir;
  ImportOptions o;
};

class ImportEach : public ImportTest, public ::testing::WithParamInterface<const char*> {};

// Image k at t = 0.01 + 0.2 k s; the joints turn 0.1 and 0.2 rad per 0.05 s, so with a
// 0.1 m radius the wheels have run 0.2 t and 0.4 t m.
TEST_P(ImportEach, JointStatesAndRawImagesReadBack) {
  joint_states();
  o.odometry_k = 1e-4;
  const auto s = run(GetParam());
  EXPECT_EQ(s.images, 5u);
  EXPECT_EQ(s.wheel_samples, 21u);
  const auto d = dataset::Dataset::load(o.out, {.check_all_images = true});
  ASSERT_EQ(d.size(), 5u);
  EXPECT_EQ(d.camera().width, 64);
  EXPECT_DOUBLE_EQ(*d.wheel_sensor().odometry_k, 1e-4);
  EXPECT_DOUBLE_EQ(d.wheel_sensor().wheel_base, 0.5);
  for (int k = 0; k < 5; ++k) {
    const cv::Mat1b img = d.image(k);
    EXPECT_EQ(img(5, 7), pixel(k, 7, 5));
    EXPECT_EQ(img(47, 63), pixel(k, 63, 47));
    const double t = 0.01 + 0.2 * k;
    EXPECT_NEAR(d.travel_at_images()[k].left, 0.2 * t, 1e-6);
    EXPECT_NEAR(d.travel_at_images()[k].right, 0.4 * t, 1e-6);
  }
}

// The odometry: an arc of radius 2 m, 0.05 rad a sample; with e = 0.5 m the right wheel runs
// 2.25 m and the left 1.75 m per radian.
TEST_P(ImportEach, OdometryPosesAndPngImagesReadBack) {
  o.image_topic = "/camera/png";
  o.odometry_topic = "/odom";
  o.wheel_base = 0.5;
  const auto s = run(GetParam());
  EXPECT_EQ(s.image_encoding, "png");
  const auto d = dataset::Dataset::load(o.out);
  ASSERT_EQ(d.wheel().size(), 21u);
  EXPECT_NEAR(d.wheel().back().travel.right, 2.25 * 1.0, 1e-6);
  EXPECT_NEAR(d.wheel().back().travel.left, 1.75 * 1.0, 1e-6);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(d.image(k)(20, 30), pixel(k, 30, 20));
  EXPECT_FALSE(d.wheel_sensor().odometry_k.has_value());
}

INSTANTIATE_TEST_SUITE_P(Recordings,
                         ImportEach,
                         ::testing::Values("ros1_none.bag",
                                           "ros1_bz2.bag",
                                           "ros1_lz4.bag",
                                           "ros2_lz4.mcap",
                                           "ros2_zstd.mcap",
                                           "ros2_nosummary.mcap",
                                           "ros2_db3",
                                           "ros2_db3_zstd"));

TEST_F(ImportTest, ImageEncodingsAreStoredLosslessly) {
  joint_states();
  for (const char* enc : {"rgb8", "bgr8", "rgba8", "bgra8"}) {
    o.image_topic = std::string("/enc/") + enc;
    o.overwrite = true;
    run("ros1_lz4.bag");
    const cv::Mat3b img =
        cv::imread(dataset::Dataset::load(o.out).images()[1].path, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(img.rows, 48) << enc;
    const int v = pixel(1, 9, 4);
    EXPECT_EQ(img(4, 9), cv::Vec3b(255 - v, v, v)) << enc;
  }
  o.image_topic = "/enc/mono16";
  run("ros1_lz4.bag");
  const auto d = dataset::Dataset::load(o.out);
  const cv::Mat1w w = cv::imread(d.images()[2].path, cv::IMREAD_UNCHANGED);
  EXPECT_EQ(w(4, 9), pixel(2, 9, 4) * 256 + 7);
  o.image_topic = "/enc/bayer_rggb8";
  run("ros1_lz4.bag");
  const auto b = dataset::Dataset::load(o.out);
  EXPECT_EQ(b.camera().pixel_format.bayer, BayerPattern::kRGGB);
  EXPECT_EQ(cv::imread(b.images()[0].path, cv::IMREAD_UNCHANGED).channels(), 1);
}

TEST_F(ImportTest, JpegImagesKeepTheirBytes) {
  joint_states();
  o.image_topic = "/camera/jpeg";
  const auto s = run("ros1_lz4.bag");
  EXPECT_EQ(s.image_encoding, "jpeg");
  const auto d = dataset::Dataset::load(o.out);
  EXPECT_EQ(d.images()[0].filename.substr(d.images()[0].filename.size() - 4), ".jpg");
  EXPECT_NEAR(d.image(4)(20, 30), pixel(4, 30, 20), 12);
}

TEST_F(ImportTest, MissingTopicListsTheTopics) {
  o.image_topic = "/nope";
  const std::string e = error("ros1_bz2.bag");
  EXPECT_NE(e.find("ros1_bz2.bag: no topic '/nope'; the recording has:"), std::string::npos) << e;
  EXPECT_NE(e.find("/joint_states"), std::string::npos) << e;
  EXPECT_NE(e.find("sensor_msgs/JointState"), std::string::npos) << e;
}

TEST_F(ImportTest, WrongTopicType) {
  o.image_topic = "/joint_states";
  const std::string e = error("ros2_db3");
  EXPECT_NE(
      e.find(
          "topic '/joint_states' is of type sensor_msgs/msg/JointState, not sensor_msgs/Image or "
          "sensor_msgs/CompressedImage"),
      std::string::npos)
      << e;
}

TEST_F(ImportTest, UnsupportedEncodingNamesTheMessage) {
  joint_states();
  o.image_topic = "/enc/yuv422";
  const std::string e = error("ros1_lz4.bag");
  EXPECT_NE(e.find("ros1_lz4.bag, topic /enc/yuv422, message 0 (recorded at 1700000000.0"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("image encoding 'yuv422' is not one we read"), std::string::npos) << e;
}

TEST_F(ImportTest, StampsGoingBackwards) {
  joint_states();
  o.image_topic = "/camera/backwards";
  const std::string e = error("ros1_lz4.bag");
  EXPECT_NE(e.find("topic /camera/backwards, message 3"), std::string::npos) << e;
  EXPECT_NE(e.find("(stamps going backwards)"), std::string::npos) << e;
}

TEST_F(ImportTest, ClocksThatDoNotOverlap) {
  joint_states();
  o.joint_states_topic = "/joint_states_late";
  const std::string e = error("ros1_lz4.bag");
  EXPECT_NE(e.find("the clocks do not overlap: the images of topic /camera/image_raw run from "
                   "1700000000.0"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("the odometry (topic /joint_states_late) from 1700000100.0"), std::string::npos)
      << e;
}

TEST_F(ImportTest, OdometryResetIsRefused) {
  o.odometry_topic = "/odom_reset";
  o.wheel_base = 0.5;
  const std::string e = error("ros1_lz4.bag");
  EXPECT_NE(e.find("topic /odom_reset, pose 12 (t = 170000000"), std::string::npos) << e;
  EXPECT_NE(e.find("odometry reset"), std::string::npos) << e;
}

TEST_F(ImportTest, WheelAngleResetIsRefused) {
  // Message 12: the angles fall from 1.1 and 2.2 rad (message 11) back to 0; with r = 0.5 m the
  // right wheel would move 1.1 m in 0.05 s.
  joint_states();
  o.joint_states_topic = "/joint_states_reset";
  o.wheel_radius = 0.5;
  const std::string e = error("ros1_lz4.bag");
  EXPECT_NE(e.find("topic /joint_states_reset, message 12 (recorded at 170000000"),
            std::string::npos)
      << e;
  EXPECT_NE(
      e.find("a wheel moves 1.100 m in 0.050 s, faster than 5 m/s (a reset of the wheel angles?)"),
      std::string::npos)
      << e;
}

// A TUM pose file covering frames 1-3 only (0.1 .. 0.7 s): a straight line at 0.5 m/s along
// yaw 0.3 rad; frames 0 and 4 are left out, the wheels run 0.5 m/s each.
TEST_F(ImportTest, TumPoseFileAndImagesOutsideTheOdometry) {
  const fs::path tum = dir / "poses.txt";
  {
    std::ofstream f(tum);
    f.precision(12);
    for (int i = 0; i <= 6; ++i) {
      const double t = 1700000000.1 + 0.1 * i, d = 0.05 * i;
      f << t << " " << d * std::cos(0.3) << " " << d * std::sin(0.3) << " 0 0 0 " << std::sin(0.15)
        << " " << std::cos(0.15) << "\n";
    }
  }
  o.poses_csv = tum.string();
  o.wheel_base = 0.5;
  o.out = (dir / "ds").string();
  const auto s = run("ros1_bz2.bag");
  EXPECT_EQ(s.images, 3u);
  EXPECT_EQ(s.images_outside, 2u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("2 image(s) outside the odometry's time span"), std::string::npos);
  const auto d = dataset::Dataset::load(o.out);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d.image(0)(3, 3), pixel(1, 3, 3));  // the first image kept is frame 1
  EXPECT_EQ(
      std::distance(fs::directory_iterator(dir / "ds" / "cam0" / "data"), fs::directory_iterator()),
      3);
  EXPECT_NEAR(d.wheel().back().travel.left, 0.3, 1e-9);
  EXPECT_NEAR(d.wheel().back().travel.right, 0.3, 1e-9);
}

TEST_F(ImportTest, ImagesWithoutStampsTakeTheRecordingTime) {
  joint_states();
  o.image_topic = "/camera/unstamped";
  const auto s = run("ros1_lz4.bag");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "5 message(s) had no header stamp (0); their recording time was used");
  const auto d = dataset::Dataset::load(o.out);
  ASSERT_EQ(d.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(static_cast<double>(d.images()[k].timestamp_ns) * 1e-9 - 1700000000.0,
                0.01 + 0.2 * k,
                1e-6);
    EXPECT_EQ(d.image(k)(1, 2), pixel(k, 2, 1));
  }
}

// Damaged recordings (1 to 8 random bytes changed, 30 draws each) either import or end with an
// InputError; never another exception, a crash or a partial dataset.
TEST_F(ImportTest, DamagedRecordingsEndWithInputErrorOnly) {
  joint_states();
  o.overwrite = true;
  std::mt19937 rng(7);
  int refused = 0, imported = 0;
  for (const char* name : {"ros1_lz4.bag", "ros1_bz2.bag", "ros2_zstd.mcap", "ros2_lz4.mcap"}) {
    std::ifstream in(kFx + "/" + name, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (int draw = 0; draw < 30; ++draw) {
      std::string bad = bytes;
      const int n = std::uniform_int_distribution<int>(1, 8)(rng);
      for (int i = 0; i < n; ++i) {
        bad[std::uniform_int_distribution<std::size_t>(0, bad.size() - 1)(rng)] =
            static_cast<char>(rng() & 0xFF);
      }
      const fs::path file = dir / (std::string("damaged_") + name);
      std::ofstream(file, std::ios::binary) << bad;
      try {
        auto rec = open_recording(file.string());
        import_recording(*rec, o);
        ++imported;
      } catch (const InputError&) {
        ++refused;
        EXPECT_FALSE(fs::exists(o.out)) << name << " draw " << draw;
      }
      fs::remove_all(o.out);
    }
  }
  EXPECT_EQ(refused + imported, 120);
  EXPECT_GT(refused, 0);
}

TEST_F(ImportTest, ExistingOutputIsKeptWithoutOverwrite) {
  joint_states();
  fs::create_directories(o.out);
  EXPECT_THROW(run("ros1_bz2.bag"), InputError);
  EXPECT_TRUE(fs::is_empty(o.out));
}

}  // namespace
}  // namespace omnivert::recording
