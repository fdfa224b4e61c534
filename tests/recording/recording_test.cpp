// The readers: topics, types and counts from the index or summary, and the messages decoded
// with the values the fixture scripts wrote (fixtures/make_ros1_bags.py, make_ros2_bags.mjs).

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "omnivert/core/error.hpp"
#include "omnivert/recording/messages.hpp"
#include "omnivert/recording/recording.hpp"

namespace omnivert::recording {
namespace {

namespace fs = std::filesystem;
const std::string kFx = OMNIVERT_RECORDING_FIXTURES;
constexpr double kT0 = 1700000000.0;

class EveryFixture : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryFixture, ListsTopicsWithTypesAndCounts) {
  auto rec = open_recording(kFx + "/" + GetParam());
  for (const auto& [topic, type, n] : {std::tuple{"/joint_states", "sensor_msgs/JointState", 21},
                                       {"/odom", "nav_msgs/Odometry", 21},
                                       {"/camera/image_raw", "sensor_msgs/Image", 5},
                                       {"/camera/png", "sensor_msgs/CompressedImage", 5}}) {
    const TopicInfo* t = rec->find(topic);
    ASSERT_NE(t, nullptr) << topic;
    EXPECT_EQ(normalized_type(t->type), type);
    EXPECT_EQ(t->count, static_cast<std::uint64_t>(n)) << topic;
  }
}

TEST_P(EveryFixture, DecodesJointStatesOdometryAndImages) {
  auto rec = open_recording(kFx + "/" + GetParam());
  int joints = 0, odoms = 0, images = 0;
  rec->read({"/joint_states", "/odom", "/camera/image_raw"}, [&](const Message& m) {
    const double i = static_cast<double>(m.index);
    if (m.topic->name == "/joint_states") {
      const auto js = decode_joint_state(m.data, rec->serialization(), "test");
      ASSERT_EQ(js.name.size(), 3u);
      EXPECT_EQ(js.name[1], "wheel_left_joint");
      EXPECT_NEAR(js.position[1], 0.1 * i, 1e-12);
      EXPECT_NEAR(js.position[2], 0.2 * i, 1e-12);
      EXPECT_NEAR(static_cast<double>(js.stamp_ns) * 1e-9 - kT0, 0.05 * i, 1e-6);
      ++joints;
    } else if (m.topic->name == "/odom") {
      const auto od = decode_odometry(m.data, rec->serialization(), "test");
      EXPECT_NEAR(od.x, 2.0 * std::sin(0.05 * i), 1e-12);
      EXPECT_NEAR(od.y, 2.0 * (1 - std::cos(0.05 * i)), 1e-12);
      EXPECT_NEAR(od.qz, std::sin(0.025 * i), 1e-12);
      ++odoms;
    } else {
      const auto im = decode_image(m.data, rec->serialization(), "test");
      EXPECT_EQ(im.width, 64u);
      EXPECT_EQ(im.height, 48u);
      EXPECT_EQ(im.encoding, "mono8");
      ASSERT_EQ(im.data.size(), 64u * 48u);
      EXPECT_EQ(im.data[5 * 64 + 7], (7 + 2 * 5 + 10 * m.index) % 256);
      ++images;
    }
  });
  EXPECT_EQ(joints, 21);
  EXPECT_EQ(odoms, 21);
  EXPECT_EQ(images, 5);
}

INSTANTIATE_TEST_SUITE_P(Recordings,
                         EveryFixture,
                         ::testing::Values("ros1_none.bag",
                                           "ros1_bz2.bag",
                                           "ros1_lz4.bag",
                                           "ros2_none.mcap",
                                           "ros2_lz4.mcap",
                                           "ros2_zstd.mcap",
                                           "ros2_nosummary.mcap",
                                           "ros2_db3",
                                           "ros2_db3_zstd",
                                           "ros2_db3/ros2_db3_0.db3"));

TEST(Recording, FormatsAndSerialisation) {
  EXPECT_EQ(open_recording(kFx + "/ros1_lz4.bag")->format(), "ROS 1 bag");
  EXPECT_EQ(open_recording(kFx + "/ros1_lz4.bag")->serialization(), Serialization::kRos1);
  EXPECT_EQ(open_recording(kFx + "/ros2_lz4.mcap")->format(), "MCAP");
  EXPECT_EQ(open_recording(kFx + "/ros2_db3")->serialization(), Serialization::kCdr);
  EXPECT_EQ(normalized_type("sensor_msgs/msg/Image"), "sensor_msgs/Image");
}

// The first `keep` bytes of a fixture, in a temporary file.
std::string truncated(const std::string& name, double keep) {
  const fs::path out =
      fs::temp_directory_path() / ("omnivert_cut_" + std::to_string(keep) + "_" + name);
  fs::copy_file(kFx + "/" + name, out, fs::copy_options::overwrite_existing);
  fs::resize_file(out, static_cast<std::uintmax_t>(static_cast<double>(fs::file_size(out)) * keep));
  return out.string();
}

std::string error_of(const std::string& path) {
  try {
    auto rec = open_recording(path);
    rec->read({"/camera/image_raw"}, [](const Message&) {});
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Recording, TruncatedFilesAreRefusedByName) {
  // Cut among the chunks: the bag header points past the end.
  const std::string bag = truncated("ros1_lz4.bag", 0.3);
  EXPECT_NE(error_of(bag).find(bag + ": the bag's index is missing"), std::string::npos)
      << error_of(bag);
  EXPECT_NE(error_of(bag).find("truncated"), std::string::npos);
  // Cut inside the index (the connection records with their message definitions).
  const std::string index = truncated("ros1_lz4.bag", 0.8);
  EXPECT_NE(error_of(index).find(index + ": connection record"), std::string::npos)
      << error_of(index);
  EXPECT_NE(error_of(index).find("(truncated recording?)"), std::string::npos);
  const std::string mcap = truncated("ros2_zstd.mcap", 0.6);
  EXPECT_NE(error_of(mcap).find(mcap + ": the MCAP file is truncated"), std::string::npos)
      << error_of(mcap);
  const std::string tiny = truncated("ros1_lz4.bag", 0.0001);
  EXPECT_NE(error_of(tiny).find(tiny), std::string::npos);
  EXPECT_NE(error_of(kFx + "/make_ros1_bags.py").find("not a recording we read"),
            std::string::npos);
  for (const auto& f : {bag, index, mcap, tiny}) fs::remove(f);
}

}  // namespace
}  // namespace omnivert::recording
