// Odometry poses turned into wheel travel (eqs. 14-15): known arcs in, known wheel travel out;
// resets, jumps and time going backwards refused with the pose's index.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/poses_to_wheels.hpp"

namespace omnivert::dataset {
namespace {

// n + 1 poses on a circle of radius r (centre at (0, r) for r > 0: turning left), yaw from 0 to
// `sweep`, one every 0.1 s.
std::vector<PoseRecord> arc(double r, double sweep, int n) {
  std::vector<PoseRecord> p;
  for (int i = 0; i <= n; ++i) {
    const double th = sweep * i / n;
    p.push_back({1'000'000'000 + i * 100'000'000LL, r * std::sin(th), r * (1 - std::cos(th)), th});
  }
  return p;
}

PosesToWheelsOptions opts(double e) { return {e, 5.0, "test"}; }

TEST(PosesToWheels, QuarterCircleGivesEachWheelItsOwnArc) {
  // Radius 2 m, e = 0.5 m, a quarter turn: right wheel on radius 2.25, left on 1.75.
  const auto w = wheel_travel_from_poses(arc(2.0, std::numbers::pi / 2, 10), opts(0.5));
  ASSERT_EQ(w.size(), 11u);
  EXPECT_DOUBLE_EQ(w.front().travel.left, 0.0);
  EXPECT_DOUBLE_EQ(w.front().travel.right, 0.0);
  EXPECT_NEAR(w.back().travel.right, 2.25 * std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(w.back().travel.left, 1.75 * std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(w[4].travel.right, 2.25 * std::numbers::pi / 2 * 0.4, 1e-12);
  EXPECT_EQ(w[4].timestamp_ns, 1'400'000'000);
}

TEST(PosesToWheels, StraightBackwardsAndTurnInPlace) {
  std::vector<PoseRecord> p = {
      {0, 1, 1, 0.3},
      {100'000'000, 1 - 0.2 * std::cos(0.3), 1 - 0.2 * std::sin(0.3), 0.3},
      {200'000'000, 1 - 0.2 * std::cos(0.3), 1 - 0.2 * std::sin(0.3), -0.1}};
  const auto w = wheel_travel_from_poses(p, opts(0.4));
  EXPECT_NEAR(w[1].travel.left, -0.2, 1e-12);  // 0.2 m backwards
  EXPECT_NEAR(w[1].travel.right, -0.2, 1e-12);
  EXPECT_NEAR(w[2].travel.left, -0.2 + 0.2 * 0.4, 1e-12);  // -0.4 rad in place: left +e/2 * 0.4
  EXPECT_NEAR(w[2].travel.right, -0.2 - 0.2 * 0.4, 1e-12);
}

TEST(PosesToWheels, TurningThroughPiWrapsTheYaw) {
  // Turning left in place from yaw 3.0 rad past pi: dtheta is +0.3, not 0.3 - 2 pi.
  std::vector<PoseRecord> p = {{0, 0, 0, 3.0},
                               {100'000'000, 0, 0, 3.0 + 0.3 - 2 * std::numbers::pi}};
  const auto w = wheel_travel_from_poses(p, opts(0.5));
  EXPECT_NEAR(w[1].travel.right, 0.25 * 0.3, 1e-12);
  EXPECT_NEAR(w[1].travel.left, -0.25 * 0.3, 1e-12);
}

TEST(PosesToWheels, ResetToZeroIsRefusedWithItsIndex) {
  auto p = arc(2.0, 1.0, 10);
  p[7].x = p[7].y = p[7].theta = 0;
  try {
    wheel_travel_from_poses(p, opts(0.5));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test, pose 7 (t = 1.700000000 s): odometry reset"),
              std::string::npos)
        << e.what();
  }
}

TEST(PosesToWheels, JumpsAndBackwardsTimeAreRefused) {
  auto p = arc(2.0, 1.0, 10);
  p[5].x += 1.0;  // 1 m in 0.1 s
  EXPECT_THROW(wheel_travel_from_poses(p, opts(0.5)), InputError);
  p = arc(2.0, 1.0, 10);
  p[5].timestamp_ns = p[4].timestamp_ns;
  EXPECT_THROW(wheel_travel_from_poses(p, opts(0.5)), InputError);
  EXPECT_THROW(wheel_travel_from_poses(arc(2.0, 1.0, 10), opts(0.0)), InputError);
}

TEST(PosesToWheels, QuaternionYawAndTumFile) {
  EXPECT_NEAR(yaw_of_quaternion(0, 0, std::sin(0.35), std::cos(0.35)), 0.7, 1e-15);
  EXPECT_NEAR(yaw_of_quaternion(0, 0, std::sin(-1.5), std::cos(-1.5)), -3.0, 1e-15);
  const auto path = std::filesystem::temp_directory_path() / "omnivert_tum_test.txt";
  {
    std::ofstream f(path);
    f << "# t x y z qx qy qz qw\n1.5 1 2 0 0 0 0.24740395925452294 0.9689124217106447\n"
      << "1.6,1.1,2,0,0,0,0,1\n";
  }
  const auto p = read_tum_poses(path.string());
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].timestamp_ns, 1'500'000'000);
  EXPECT_NEAR(p[0].theta, 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(p[1].x, 1.1);
  {
    std::ofstream f(path);
    f << "1.5 1 2 0 0 0\n";
  }
  try {
    read_tum_poses(path.string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 1);
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace omnivert::dataset
