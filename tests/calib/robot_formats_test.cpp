// The robot-format files (calib/robot_formats.hpp) of a known mounting: camera centre at
// (0.1, 0.05) m in the base frame, camera yaw 30 degrees. The exact strings a user pastes, each
// file read back into the same transform, the covariance's REP-103 order and propagation, the
// frame names and the camera height.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "omnivert/calib/robot_formats.hpp"
#include "omnivert/core/angles.hpp"
#include "robot_formats_parse.hpp"

namespace omnivert::calib {
namespace {

using ::testing::HasSubstr;
using testing::parse_ros1_line;
using testing::parse_ros2_line;
using testing::parse_urdf_joint;
using testing::parse_yaml_matrix;

// Camera at (0.1, 0.05) m, yaw 30 degrees, as (phi, rho, psi) of Fig. 19.
Extrinsics known_mounting() {
  const double phi = std::atan2(0.05, 0.1);
  return {phi, std::hypot(0.1, 0.05), deg2rad(30.0) - phi};
}

Eigen::Matrix3d known_covariance() {
  Eigen::Matrix3d C;
  C << 1e-4, 2e-6, -5e-5,  //
      2e-6, 4e-6, 1e-6,    //
      -5e-5, 1e-6, 9e-5;
  return C;
}

TEST(RobotFormats, KnownMountingGivesTheExpectedLines) {
  const RobotFrames f;
  const MountingTransform m = mounting_transform(known_mounting(), known_covariance(), f);
  const std::string urdf = urdf_joint(m, f);
  EXPECT_THAT(urdf, HasSubstr("<joint name=\"base_link_to_camera_link\" type=\"fixed\">"));
  EXPECT_THAT(urdf, HasSubstr("<parent link=\"base_link\"/>"));
  EXPECT_THAT(urdf, HasSubstr("<child link=\"camera_link\"/>"));
  EXPECT_THAT(urdf, HasSubstr("<origin xyz=\"0.1 0.05 0\" rpy=\"0 0 0.5235987756\"/>"));
  EXPECT_THAT(urdf, HasSubstr("p_base = T_base_cam p_cam"));
  EXPECT_THAT(urdf, HasSubstr("z = 0 (the camera height is not estimated"));

  const std::string cmd = static_transform_commands(m, f);
  EXPECT_THAT(cmd,
              HasSubstr("\nrosrun tf static_transform_publisher 0.1 0.05 0 0.5235987756 0 0 "
                        "base_link camera_link 100\n"));
  EXPECT_THAT(cmd,
              HasSubstr("\nrosrun tf2_ros static_transform_publisher 0.1 0.05 0 0.5235987756 0 0 "
                        "base_link camera_link\n"));
  EXPECT_THAT(cmd,
              HasSubstr("\nros2 run tf2_ros static_transform_publisher --x 0.1 --y 0.05 --z 0 "
                        "--yaw 0.5235987756 --pitch 0 --roll 0 --frame-id base_link "
                        "--child-frame-id camera_link\n"));

  const std::string yaml = kalibr_yaml(m, f);
  EXPECT_THAT(yaml,
              HasSubstr("\nT_base_cam:\n  - [0.8660254038, -0.5, 0, 0.1]\n"
                        "  - [0.5, 0.8660254038, 0, 0.05]\n  - [0, 0, 1, 0]\n"
                        "  - [0, 0, 0, 1]\n"));
  // T_cam_base = [R^T | -R^T t]: -(c 0.1 + s 0.05, -s 0.1 + c 0.05).
  EXPECT_THAT(yaml,
              HasSubstr("\nT_cam_base:\n  - [0.8660254038, 0.5, 0, -0.1116025404]\n"
                        "  - [-0.5, 0.8660254038, 0, 0.006698729811]\n"));
  EXPECT_THAT(yaml, HasSubstr("\nquaternion_xyzw: [0, 0, 0.2588190451, 0.9659258263]\n"));
  EXPECT_THAT(yaml,
              HasSubstr("\nestimated: {x: true, y: true, z: false, roll: false, "
                        "pitch: false, yaw: true}\n"));
  EXPECT_THAT(yaml, HasSubstr("\ncovariance_order: [x, y, z, roll, pitch, yaw]\n"));
}

TEST(RobotFormats, EveryFileReadsBackAsTBaseCam) {
  const RobotFrames f{"odom_base", "omni_cam", 0.42};
  const Extrinsics e{-0.34, 0.23, 0.33 + 3.0};  // the yaw wraps across +-pi
  const MountingTransform m = mounting_transform(e, known_covariance(), f);
  Eigen::Matrix4d expected = e.T_base_cam();
  expected(2, 3) = 0.42;
  const std::string cmd = static_transform_commands(m, f);
  const std::string yaml = kalibr_yaml(m, f);
  const testing::ParsedTransform parsed[] = {
      parse_urdf_joint(urdf_joint(m, f)),
      parse_ros1_line(cmd, "rosrun tf static_transform_publisher"),
      parse_ros1_line(cmd, "rosrun tf2_ros static_transform_publisher"),
      parse_ros2_line(cmd)};
  for (const auto& p : parsed) {
    ASSERT_TRUE(p.found);
    EXPECT_EQ(p.parent, "odom_base");
    EXPECT_EQ(p.child, "omni_cam");
    EXPECT_LT((p.T - expected).cwiseAbs().maxCoeff(), 1e-9) << p.T;
  }
  EXPECT_LT((parse_yaml_matrix(yaml, "T_base_cam") - expected).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((parse_yaml_matrix(yaml, "T_cam_base") * expected - Eigen::Matrix4d::Identity())
                .cwiseAbs()
                .maxCoeff(),
            1e-9);
  EXPECT_THAT(yaml, HasSubstr("base_frame: odom_base\ncamera_frame: omni_cam\n"));
  EXPECT_THAT(yaml, HasSubstr("z = 0.42 m (the camera height given to calibrate, not estimated)"));
}

// Covariance: J C J^T with J = d(x, y, yaw)/d(phi, rho, psi), against central differences, in
// rows and columns 0, 1, 5; z, roll and pitch rows and columns zero.
TEST(RobotFormats, CovarianceIsPropagatedIntoRep103Order) {
  const Extrinsics e = known_mounting();
  const Eigen::Matrix3d C = known_covariance();
  const MountingTransform m = mounting_transform(e, C);
  auto f = [](const Eigen::Vector3d& v) {
    const Extrinsics x = Extrinsics::from_vec(v);
    return Eigen::Vector3d(x.position()(0), x.position()(1), v(0) + v(2));
  };
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(i) = 1e-6;
    J.col(i) = (f(e.vec() + d) - f(e.vec() - d)) / 2e-6;
  }
  const Eigen::Matrix3d expected = J * C * J.transpose();
  const int idx[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(m.covariance(idx[i], idx[j]), expected(i, j), 1e-12) << i << "," << j;
  for (int k : {2, 3, 4}) {
    EXPECT_EQ(m.covariance.row(k).cwiseAbs().sum(), 0.0);
    EXPECT_EQ(m.covariance.col(k).cwiseAbs().sum(), 0.0);
  }
  // sigma_yaw^2 = C_phiphi + C_psipsi + 2 C_phipsi = 1e-4 + 9e-5 - 1e-4.
  EXPECT_NEAR(m.covariance(5, 5), 9e-5, 1e-15);
  EXPECT_THAT(kalibr_yaml(m, {}), HasSubstr("yaw: " + std::string("0.009486832981")));
}

TEST(RobotFormats, FrameNamesAreChecked) {
  std::string why;
  EXPECT_TRUE(RobotFrames{}.IsValid(&why));
  EXPECT_FALSE((RobotFrames{"base link", "camera_link", {}}.IsValid(&why)));
  EXPECT_THAT(why, HasSubstr("'base link'"));
  EXPECT_FALSE((RobotFrames{"base_link", "", {}}.IsValid(&why)));
  EXPECT_FALSE((RobotFrames{"base_link", "cam\"", {}}.IsValid(&why)));
  EXPECT_FALSE((RobotFrames{"a", "a", {}}.IsValid(&why)));
  EXPECT_FALSE((RobotFrames{"a", "b", NAN}.IsValid(&why)));
}

}  // namespace
}  // namespace omnivert::calib
