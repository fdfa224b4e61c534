// The robot's description in a recording: static transforms composed along the frame tree,
// the camera's mount in the paper's (phi, rho, psi), the wheels of a URDF; and the import on
// the fixtures written by the independent writers (make_ros1_bags.py's ros1_description.bag,
// make_ros2_bags.mjs's ros2_description.mcap), whose mounts and wheels are known by
// construction.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/recording/import.hpp"
#include "omnivert/recording/robot_description.hpp"

namespace omnivert::recording {
namespace {

namespace fs = std::filesystem;
const std::string kFx = OMNIVERT_RECORDING_FIXTURES;
constexpr double kPi = std::numbers::pi;

Eigen::Isometry3d pose(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

TEST(FrameTree, ComposesThroughTheCommonAncestor) {
  // root -> a -> b and root -> c: T_c_b = T_root_c^-1 T_root_a T_a_b.
  const Eigen::Isometry3d ra = pose(1, 2, 0, 0.3), ab = pose(-0.5, 0.25, 1, -1.1),
                          rc = pose(0.2, -3, 0.5, 2.0);
  FrameTree t;
  t.add({"a", "b", ab});
  t.add({"root", "a", ra});
  t.add({"root", "c", rc});
  const auto cb = t.transform("c", "b");
  ASSERT_TRUE(cb);
  EXPECT_LT((cb->matrix() - (rc.inverse() * ra * ab).matrix()).norm(), 1e-12);
  const auto bc = t.transform("b", "c");  // the other direction: the inverse
  ASSERT_TRUE(bc);
  EXPECT_LT((bc->matrix() - cb->inverse().matrix()).norm(), 1e-12);
  EXPECT_LT((t.transform("a", "a")->matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-15);
  std::string why;
  EXPECT_FALSE(t.transform("root", "camera", &why));
  EXPECT_EQ(why, "no frame 'camera' (frames: a, b, c, root)");
  t.add({"odom", "x", pose(0, 0, 0, 0)});
  EXPECT_FALSE(t.transform("x", "b", &why));
  EXPECT_EQ(why, "frames 'x' and 'b' are not connected");
}

// T_base_cam = [Rz(phi + psi) | (rho cos phi, rho sin phi, z)] (conventions.md) read back.
TEST(CameraMount, InvertsTheConvention) {
  for (const double phi : {-2.9, -0.4, 0.0, 1.3, 3.0})
    for (const double psi : {-3.0, -0.2, 0.7, 2.5}) {
      const double rho = 0.23, z = 0.41;
      const CameraMount m =
          camera_mount(pose(rho * std::cos(phi), rho * std::sin(phi), z, phi + psi));
      EXPECT_NEAR(m.phi, phi, 1e-12);
      EXPECT_NEAR(m.rho, rho, 1e-12);
      EXPECT_NEAR(angle_diff(m.psi, psi), 0.0, 1e-12);
      EXPECT_NEAR(m.height, z, 1e-12);
      EXPECT_NEAR(m.tilt, 0.0, 1e-7);
    }
  const CameraMount centred = camera_mount(pose(0, 0, 0.3, 0.5));
  EXPECT_EQ(centred.phi, 0.0);
  EXPECT_NEAR(centred.psi, 0.5, 1e-15);
  // An optical frame (z forward): tilted by 90 degrees.
  Eigen::Isometry3d optical = pose(0.1, 0, 0.3, 0);
  optical.linear() = Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(camera_mount(optical).tilt, kPi / 2, 1e-12);
}

const char* kUrdf = R"(<robot name="r">
  <link name="base_link"/>
  <link name="l"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <link name="r"><visual><geometry><cylinder radius="0.07" length="0.02"/></geometry></visual></link>
  <joint name="jl" type="continuous"><parent link="base_link"/><child link="l"/>
    <origin xyz="0.01 0.2 0.05" rpy="-1.5707963 0 0"/></joint>
  <joint name="jr" type="continuous"><parent link="base_link"/><child link="r"/>
    <origin xyz="0.01 -0.1 0.05" rpy="1.5707963 0 0.3"/></joint>
</robot>)";

TEST(Urdf, WheelBaseIsTheDistanceOfTheWheelJoints) {
  const Urdf u = parse_urdf(kUrdf, "test");
  const UrdfWheels w = urdf_wheels(u, "jl", "jr", "test");
  EXPECT_NEAR(w.wheel_base, 0.3, 1e-12);
  ASSERT_TRUE(w.wheel_radius);
  EXPECT_NEAR(*w.wheel_radius, 0.06, 1e-15);  // the mean of the two cylinders
  EXPECT_THROW(urdf_wheels(u, "jl", "wheel_right_joint", "test"), InputError);
  try {
    parse_urdf("<robot><joint name='x'><parent link='a'/></joint></robot>", "rec, topic /rd");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "rec, topic /rd: a URDF joint without a name, a parent or a child link (line 1)");
  }
  EXPECT_THROW(parse_urdf("<robot><joint", "x"), InputError);
}

class ImportDescription : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_description_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    o.out = (dir / "ds").string();
    o.image_topic = "/camera/image_raw";
    o.joint_states_topic = "/joint_states";
    o.left_joint = "wheel_left_joint";
    o.right_joint = "wheel_right_joint";
  }
  void TearDown() override { fs::remove_all(dir); }
  ImportSummary run(const std::string& fixture) {
    auto rec = open_recording(kFx + "/" + fixture);
    return import_recording(*rec, o);
  }
  // The mount of the summary and of the dataset's prior.yaml, both against (x, y, z, yaw).
  void expect_mount(const ImportSummary& s, double x, double y, double z, double yaw) {
    ASSERT_TRUE(s.mount) << s.mount_source;
    const double phi = std::atan2(y, x), rho = std::hypot(x, y), psi = wrap_angle(yaw - phi);
    EXPECT_NEAR(s.mount->phi, phi, 1e-9);
    EXPECT_NEAR(s.mount->rho, rho, 1e-9);
    EXPECT_NEAR(s.mount->psi, psi, 1e-9);
    EXPECT_NEAR(s.mount->height, z, 1e-9);
    const YAML::Node p = YAML::LoadFile((fs::path(o.out) / kPriorFile).string());
    EXPECT_NEAR(p["phi"].as<double>(), phi, 1e-9);
    EXPECT_NEAR(p["rho"].as<double>(), rho, 1e-9);
    EXPECT_NEAR(p["psi"].as<double>(), psi, 1e-9);
    EXPECT_NEAR(p["camera_height"].as<double>(), z, 1e-9);
    EXPECT_EQ(p["base_frame"].as<std::string>(), "base_link");
    EXPECT_EQ(p["camera_frame"].as<std::string>(), "omni_camera");
  }
  // The wheels of the fixtures' URDF: base 0.16 m, radius 0.033 m; the joints turn 0.1 and
  // 0.2 rad per sample.
  void expect_wheels(const ImportSummary& s) {
    EXPECT_TRUE(s.wheel_base_from_description);
    EXPECT_TRUE(s.wheel_radius_from_description);
    EXPECT_NEAR(s.wheel_base, 0.16, 1e-12);
    EXPECT_NEAR(s.wheel_radius, 0.033, 1e-15);
    const auto d = dataset::Dataset::load(o.out);
    EXPECT_NEAR(d.wheel_sensor().wheel_base, 0.16, 1e-12);
    ASSERT_EQ(d.wheel().size(), 21u);
    for (std::size_t i = 0; i < d.wheel().size(); ++i) {
      EXPECT_NEAR(d.wheel()[i].travel.left, 0.1 * 0.033 * static_cast<double>(i), 1e-12);
      EXPECT_NEAR(d.wheel()[i].travel.right, 0.2 * 0.033 * static_cast<double>(i), 1e-12);
    }
  }
  fs::path dir;
  ImportOptions o;
};

// make_ros1_bags.py's TF_STATIC: base_link -> camera_mount -> omni_camera puts the camera at
// (0.1, 0.2, 0.35), its x axis at 45 degrees.
TEST_F(ImportDescription, Ros1MountAndWheelsFromTheRecording) {
  const ImportSummary s = run("ros1_description.bag");
  expect_mount(s, 0.1, 0.2, 0.35, kPi / 4);
  EXPECT_EQ(s.mount_source,
            "/tf_static of " + kFx + "/ros1_description.bag (base_link -> omni_camera)");
  expect_wheels(s);
}

// make_ros2_bags.mjs's TF_STATIC: the camera at (-0.1, 0.15, 0.4) in base_link, its x axis at
// -150 degrees, through base_footprint (the inverse of base_footprint -> base_link).
TEST_F(ImportDescription, Ros2MountAndWheelsFromTheRecording) {
  const ImportSummary s = run("ros2_description.mcap");
  expect_mount(s, -0.1, 0.15, 0.4, deg2rad(-150.0));
  expect_wheels(s);
}

TEST_F(ImportDescription, FlagsWinOverTheDescription) {
  o.wheel_base = 0.5;
  o.wheel_radius = 0.1;
  const ImportSummary s = run("ros1_description.bag");
  EXPECT_FALSE(s.wheel_base_from_description);
  EXPECT_FALSE(s.wheel_radius_from_description);
  const auto d = dataset::Dataset::load(o.out);
  EXPECT_DOUBLE_EQ(d.wheel_sensor().wheel_base, 0.5);
  EXPECT_NEAR(d.wheel().back().travel.right, 0.2 * 0.1 * 20, 1e-12);
}

TEST_F(ImportDescription, ACameraFrameNotInTheTreeGivesNoPrior) {
  o.camera_frame = "camera_link";
  const ImportSummary s = run("ros1_description.bag");
  EXPECT_FALSE(s.mount);
  EXPECT_FALSE(fs::exists(fs::path(o.out) / kPriorFile));
  EXPECT_EQ(s.mount_source,
            "/tf_static of " + kFx +
                "/ros1_description.bag has no transform base_link -> camera_link: no frame "
                "'camera_link' (frames: base_footprint, base_link, camera_mount, laser, "
                "omni_camera)");
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_EQ(s.warnings.back(), s.mount_source + "; the prior is calibrate's default or its flags");
}

TEST_F(ImportDescription, WithoutADescriptionTheWheelsAreNeeded) {
  try {
    run("ros1_none.bag");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--joint-states-topic needs --wheel-joints LEFT,RIGHT and --wheel-radius");
  }
  const ImportSummary s = [&] {
    o.wheel_radius = 0.1;
    o.wheel_base = 0.5;
    return run("ros1_none.bag");
  }();
  EXPECT_FALSE(s.mount);
  EXPECT_EQ(s.mount_source, "the recording has no /tf_static");
}

}  // namespace
}  // namespace omnivert::recording
