// The robot-format files of a calibration (calib/robot_formats.hpp) against the simulator's
// truth: each written transform (the URDF joint's origin, the ROS 1 and ROS 2
// static_transform_publisher lines, the YAML's T_base_cam and T_cam_base), read back as text
// and composed with the inverse of the true T_base_cam, is the identity within the estimate's
// covariance; the frames and the camera height are those given.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../calib/robot_formats_parse.hpp"
#include "calibration_fixture.hpp"
#include "omnivert/calib/robot_formats.hpp"

namespace omnivert::testing {
namespace {

using pipeline::calibrate_dataset;
using ::testing::HasSubstr;

class CalibrateRobotFormats : public CalibrationDatasets {};

// (x, y, yaw) of E = T_truth^-1 T_estimate, in the base frame's axes (the translation error
// rotated back into them), and E's z, roll and pitch parts.
struct Difference {
  Eigen::Vector3d xy_yaw;
  double z = 0, tilt = 0;
};

Difference difference(const Eigen::Matrix4d& truth, const Eigen::Matrix4d& estimate) {
  const Eigen::Matrix4d E = truth.inverse() * estimate;
  Difference d;
  const Eigen::Vector3d t = truth.block<3, 3>(0, 0) * E.block<3, 1>(0, 3);
  d.xy_yaw = {t(0), t(1), std::atan2(E(1, 0), E(0, 0))};
  d.z = t(2);
  d.tilt = std::acos(std::clamp(E(2, 2), -1.0, 1.0));
  return d;
}

TEST_F(CalibrateRobotFormats, EveryWrittenTransformComposedWithTheTruthIsTheIdentity) {
  const fs::path out = scratch("robot-formats");
  auto o = cli_defaults_refined();
  o.frames = {"base_footprint", "omni_camera", 0.9};  // the simulator's camera height
  const auto r = calibrate_dataset(paper().string(), out.string(), o);
  expect_complete_outputs_without_nan(out);
  ASSERT_TRUE(r.wrote_extrinsics);
  ASSERT_TRUE(r.truth.has_value());
  calib::Extrinsics truth{r.truth->phi, r.truth->rho, r.truth->psi};
  Eigen::Matrix4d T_truth = truth.T_base_cam();
  T_truth(2, 3) = 0.9;
  const calib::MountingTransform m =
      calib::mounting_transform(r.extrinsics(), r.calibration.covariance, o.frames);
  Eigen::Matrix3d C;  // (x, y, yaw) block of the written REP-103 covariance
  const int idx[3] = {0, 1, 5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C(i, j) = m.covariance(idx[i], idx[j]);

  const std::string cmd = read_text(out / "static_transform_publisher.sh");
  const std::string yaml = read_text(out / "extrinsics_kalibr.yaml");
  const ParsedTransform parsed[] = {
      parse_urdf_joint(read_text(out / "camera_joint.urdf")),
      parse_ros1_line(cmd, "rosrun tf static_transform_publisher"),
      parse_ros1_line(cmd, "rosrun tf2_ros static_transform_publisher"),
      parse_ros2_line(cmd)};
  std::vector<Eigen::Matrix4d> written;
  for (const ParsedTransform& p : parsed) {
    ASSERT_TRUE(p.found);
    EXPECT_EQ(p.parent, "base_footprint");
    EXPECT_EQ(p.child, "omni_camera");
    written.push_back(p.T);
  }
  written.push_back(parse_yaml_matrix(yaml, "T_base_cam"));
  written.push_back(parse_yaml_matrix(yaml, "T_cam_base").inverse());
  for (const Eigen::Matrix4d& T : written) {
    ASSERT_TRUE(T.allFinite());
    const Difference d = difference(T_truth, T);
    // Within the estimate's covariance: the 0.1% point of chi-square with 3 degrees of freedom
    // (the NEES bound of CalibrateDataset.PaperRunWithRefinementIsWithinToleranceOfTheTruth).
    const double nees = d.xy_yaw.dot(C.ldlt().solve(d.xy_yaw));
    EXPECT_LE(nees, 16.3) << "error (x, y, yaw) " << d.xy_yaw.transpose();
    EXPECT_NEAR(d.z, 0.0, 1e-9);
    EXPECT_NEAR(d.tilt, 0.0, 1e-6);
    // Read the other way round (T_cam_base where T_base_cam belongs), it would be off by
    // twice the camera's offset: far outside the covariance.
    const double wrong = difference(T_truth, T.inverse()).xy_yaw.head<2>().norm();
    EXPECT_GT(wrong, 0.1);
  }
}

}  // namespace
}  // namespace omnivert::testing
