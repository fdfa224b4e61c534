// sensor_msgs/LaserScan imported into laser0/ from a ROS 1 bag written by python3-rosbag
// (fixtures/make_laser_bag.py) and a ROS 2 MCAP file written by @mcap/core and
// @foxglove/rosmsg2-serialization (fixtures/make_laser_mcap.mjs): the scans read back with the
// fixtures' numbers, NaN and inf ranges kept as no returns, and the scanner pose required.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/laser.hpp"
#include "omnivert/recording/import.hpp"

namespace omnivert::recording {
namespace {

namespace fs = std::filesystem;
const std::string kFx = OMNIVERT_RECORDING_FIXTURES;

class LaserImport : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_laser_import_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    o.out = (dir / "ds").string();
    o.image_topic = "/camera/image_raw";
    o.joint_states_topic = "/joint_states";
    o.left_joint = "wheel_left_joint";
    o.right_joint = "wheel_right_joint";
    o.wheel_radius = 0.1;
    o.wheel_base = 0.5;
    o.laser_topic = "/scan";
    o.laser_pose = dataset::LaserSensor{0.12, -0.03, 0.05, 0.0};
  }
  void TearDown() override { fs::remove_all(dir); }
  ImportSummary run(const std::string& fixture = "ros1_laser.bag") {
    auto rec = open_recording(kFx + "/" + fixture);
    return import_recording(*rec, o);
  }
  // The fixtures' scans: 11 at 10 Hz from T0 + 30 ms, 8 rays over -90..90 degrees, ray i at
  // 1 + 0.5 i + 0.01 k m, ray 2 NaN and ray 5 +inf. `stamp_ns`: the stamps' tolerance.
  void check_scans(const std::string& fixture, double stamp_ns);
  fs::path dir;
  ImportOptions o;
};

void LaserImport::check_scans(const std::string& fixture, double stamp_ns) {
  fs::remove_all(o.out);
  const ImportSummary s = run(fixture);
  EXPECT_EQ(s.laser_scans, 11u);
  const auto laser = dataset::load_laser(o.out);
  ASSERT_TRUE(laser.has_value());
  EXPECT_DOUBLE_EQ(laser->sensor.x, 0.12);
  EXPECT_DOUBLE_EQ(laser->sensor.y, -0.03);
  EXPECT_DOUBLE_EQ(laser->sensor.yaw, 0.05);
  ASSERT_EQ(laser->scans.size(), 11u);
  EXPECT_EQ(laser->non_finite, 22u);  // ray 2 NaN and ray 5 inf in each scan
  for (std::size_t k = 0; k < laser->scans.size(); ++k) {
    const dataset::LaserScan& sc = laser->scans[k];
    // Within `stamp_ns` of the fixture writer's stamps (ROS 1: doubles of seconds near 1.7e9).
    const std::int64_t expected =
        1'700'000'000'030'000'000 + 100'000'000 * static_cast<std::int64_t>(k);
    EXPECT_NEAR(static_cast<double>(sc.timestamp_ns - expected), 0.0, stamp_ns);
    EXPECT_NEAR(sc.angle_min, -M_PI / 2, 1e-6);
    EXPECT_NEAR(sc.angle_increment, M_PI / 7, 1e-6);
    EXPECT_NEAR(sc.range_min, 0.1, 1e-6);
    EXPECT_NEAR(sc.range_max, 10.0, 1e-6);
    ASSERT_EQ(sc.ranges.size(), 8u);
    for (std::size_t i = 0; i < 8; ++i) {
      if (i == 2) {
        EXPECT_TRUE(std::isnan(sc.ranges[i]));
      } else if (i == 5) {
        EXPECT_TRUE(std::isinf(sc.ranges[i]) && sc.ranges[i] > 0);
      } else {
        EXPECT_NEAR(sc.ranges[i], 1.0 + 0.5 * i + 0.01 * k, 1e-4);
      }
    }
  }
}

TEST_F(LaserImport, Ros1BagScansReadBack) {
  // python3-rosbag's stamps are doubles of seconds near 1.7e9: exact to a few hundred ns.
  check_scans("ros1_laser.bag", 1000.0);
}

TEST_F(LaserImport, Ros2McapScansReadBack) { check_scans("ros2_laser.mcap", 0.0); }

TEST_F(LaserImport, ScannerPoseIsRequired) {
  o.laser_pose.reset();
  std::string what = "no error";
  try {
    run();
  } catch (const InputError& e) {
    what = e.what();
  }
  EXPECT_EQ(what, "--laser-topic needs --laser-pose X Y YAW: the scanner's pose on the robot");
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST_F(LaserImport, TopicOfAnotherTypeIsRefused) {
  o.laser_topic = "/joint_states";
  std::string what = "no error";
  try {
    run();
  } catch (const InputError& e) {
    what = e.what();
  }
  EXPECT_EQ(what,
            kFx +
                "/ros1_laser.bag: topic '/joint_states' is of type "
                "sensor_msgs/JointState, not sensor_msgs/LaserScan");
}

}  // namespace
}  // namespace omnivert::recording
