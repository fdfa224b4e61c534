// Analytic Jacobians of the calibration models (appendix A.4 and the inverse-distance
// variants) against central differences at random states; the observation model against
// direct geometry.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <functional>
#include <random>
#include <set>

#include "calib/propagator.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {
namespace {

constexpr double kE = 0.5;
constexpr double kTol = 1e-6;  // absolute, on Jacobian entries of order 1

// Central differences of f: R^n -> R^m, step h, wrapping angle outputs when asked.
Eigen::MatrixXd numeric_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                 const Eigen::VectorXd& x,
                                 bool wrap_output = false) {
  const double h = 1e-6;
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    Eigen::VectorXd d = f(xp) - f(xm);
    if (wrap_output)
      for (int k = 0; k < d.size(); ++k) d(k) = wrap_angle(d(k));
    J.col(i) = d / (2 * h);
  }
  return J;
}

struct RandomStates : ::testing::Test {
  std::mt19937_64 rng{42};
  double U(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
};

TEST_F(RandomStates, PropagationJacobiansAB) {
  for (int trial = 0; trial < 50; ++trial) {
    const Vec2 x(U(1.0, 8.0), U(-kPi, kPi));
    const double dR = U(-0.05, 0.05), dL = U(-0.05, 0.05);
    Mat2 A, B;
    propagate_feature(x, dR, dL, kE, &A, &B);
    auto fx = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return propagate_feature(v, dR, dL, kE);
    };
    auto fu = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      return propagate_feature(x, u(0), u(1), kE);
    };
    EXPECT_LT((A - numeric_jacobian(fx, x)).cwiseAbs().maxCoeff(), kTol);
    EXPECT_LT((B - numeric_jacobian(fu, Eigen::Vector2d(dR, dL))).cwiseAbs().maxCoeff(), kTol);
    // Appendix A.4 printed form of A^i and B^i (eq. 32).
    const double dr = 0.5 * (dR + dL), D = x(0), th = x(1);
    Mat2 A_paper, B_paper;
    A_paper << 1, -dr * std::sin(th), dr / (D * D) * std::sin(th), 1 - dr / D * std::cos(th);
    B_paper << std::cos(th) / 2, std::cos(th) / 2, 1 / kE - std::sin(th) / (2 * D),
        -1 / kE - std::sin(th) / (2 * D);
    EXPECT_LT((A - A_paper).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LT((B - B_paper).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST_F(RandomStates, InversePropagationJacobiansAndEquivalence) {
  for (int trial = 0; trial < 50; ++trial) {
    const Vec2 x(U(0.1, 1.0), U(-kPi, kPi));
    const double dR = U(-0.05, 0.05), dL = U(-0.05, 0.05);
    Mat2 A, B;
    const Vec2 y = propagate_feature_inverse(x, dR, dL, kE, &A, &B);
    auto fx = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return propagate_feature_inverse(v, dR, dL, kE);
    };
    auto fu = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      return propagate_feature_inverse(x, u(0), u(1), kE);
    };
    EXPECT_LT((A - numeric_jacobian(fx, x)).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_LT((B - numeric_jacobian(fu, Eigen::Vector2d(dR, dL))).cwiseAbs().maxCoeff(), 1e-5);
    // Same motion as eq. (29) in (D, theta).
    const Vec2 yd = propagate_feature(Vec2(1.0 / x(0), x(1)), dR, dL, kE);
    EXPECT_NEAR(1.0 / y(0), yd(0), 1e-12);
    EXPECT_NEAR(y(1), yd(1), 1e-12);
  }
}

TEST_F(RandomStates, ObservationJacobianH) {
  for (int trial = 0; trial < 50; ++trial) {
    const Extrinsics ex{U(-kPi, kPi), U(0.05, 0.5), U(-kPi, kPi)};
    const double D = U(1.0, 8.0), th = U(-kPi, kPi);
    Row5 H;
    predict_bearing(D, th, ex, &H);
    auto f = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return Eigen::VectorXd::Constant(1, predict_bearing(v(0), v(1), {v(2), v(3), v(4)}));
    };
    Eigen::VectorXd x(5);
    x << D, th, ex.phi, ex.rho, ex.psi;
    EXPECT_LT((H - numeric_jacobian(f, x, true)).cwiseAbs().maxCoeff(), kTol) << "trial " << trial;
    EXPECT_DOUBLE_EQ(H(1), H(2));  // H3 = H2 (NOTES Sec. 5)
    EXPECT_EQ(H(4), -1.0);

    // Inverse distance: same bearing, chain-rule Jacobian.
    Row5 Hq;
    const double bq = predict_bearing_inverse(1.0 / D, th, ex, &Hq);
    EXPECT_NEAR(angle_diff(bq, predict_bearing(D, th, ex)), 0.0, 1e-12);
    auto fq = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return Eigen::VectorXd::Constant(1, predict_bearing_inverse(v(0), v(1), {v(2), v(3), v(4)}));
    };
    x(0) = 1.0 / D;
    EXPECT_LT((Hq - numeric_jacobian(fq, x, true)).cwiseAbs().maxCoeff(), kTol);
    EXPECT_NEAR(Hq(0), H(0) * (-D * D), 1e-9);
  }
}

TEST_F(RandomStates, ObservationAgreesWithGeometry) {
  // Eq. (27) from (D, theta) equals atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi).
  for (int trial = 0; trial < 200; ++trial) {
    const Extrinsics ex{U(-kPi, kPi), U(0.0, 0.5), U(-kPi, kPi)};
    const Eigen::Vector3d pose(U(-5, 5), U(-5, 5), U(-kPi, kPi));
    const Eigen::Vector2d f =
        pose.head<2>() + U(1.0, 8.0) * Eigen::Vector2d(std::cos(U(0, 7)), std::sin(U(0, 7)));
    const Vec2 Dt = feature_from_world(pose, f);
    EXPECT_NEAR(angle_diff(predict_bearing(Dt(0), Dt(1), ex), bearing_from_geometry(pose, f, ex)),
                0.0,
                1e-12);
    EXPECT_LT((feature_to_world(pose, Dt(0), Dt(1)) - f).norm(), 1e-12);
  }
  // A hand case: robot at origin facing +x, camera at the origin (rho = 0), feature at (0, 2):
  // bearing +90 degrees; with phi + psi = 90 degrees it is 0.
  const Eigen::Vector3d pose(0, 0, 0);
  EXPECT_NEAR(bearing_from_geometry(pose, {0, 2}, {0.0, 0.0, 0.0}), kPi / 2, 1e-15);
  EXPECT_NEAR(bearing_from_geometry(pose, {0, 2}, {0.3, 0.0, kPi / 2 - 0.3}), 0.0, 1e-15);
  // Camera 1 m ahead (phi = 0, rho = 1), feature at (2, 1): 45 degrees.
  EXPECT_NEAR(bearing_from_geometry(pose, {2, 1}, {0.0, 1.0, 0.0}), kPi / 4, 1e-15);
}

TEST_F(RandomStates, FeatureFromRayJacobiansAndRoundTrip) {
  for (int trial = 0; trial < 50; ++trial) {
    const Extrinsics ex{U(-kPi, kPi), U(0.05, 0.5), U(-kPi, kPi)};
    const double qc = U(0.1, 0.8), beta = U(-kPi, kPi);
    Mat2 J_in;
    Mat23 J_ex;
    const Vec2 y = feature_from_ray(qc, beta, ex, &J_in, &J_ex);
    // The feature lies on the ray: its predicted bearing is beta.
    EXPECT_NEAR(angle_diff(predict_bearing_inverse(y(0), y(1), ex), beta), 0.0, 1e-12);
    Eigen::VectorXd x(5);
    x << qc, beta, ex.phi, ex.rho, ex.psi;
    auto f = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return feature_from_ray(v(0), v(1), {v(2), v(3), v(4)});
    };
    const Eigen::MatrixXd Jn = numeric_jacobian(f, x);
    Eigen::Matrix<double, 2, 5> J;
    J << J_in, J_ex;
    // theta is an angle: compare the wrapped numeric difference.
    Eigen::MatrixXd Jw = Jn;
    for (int i = 0; i < 5; ++i) Jw(1, i) = Jn(1, i);
    EXPECT_LT((J - Jw).cwiseAbs().maxCoeff(), 1e-5) << "trial " << trial;
  }
}

TEST_F(RandomStates, InvariantParametrisationJacobians) {
  for (int trial = 0; trial < 50; ++trial) {
    const double dR = U(-0.05, 0.05), dL = U(-0.05, 0.05);
    const Vec2 p(U(-6, 6), U(-6, 6));
    const Vec4 f(U(-0.5, 0.5), U(-0.5, 0.5), U(-kPi, kPi), U(0.05, 1.0));
    const Vec3 cam(U(-0.4, 0.4), U(-0.4, 0.4), U(-kPi, kPi));
    Mat2 Jp, Jpu;
    const Vec2 p1 = propagate_point(p, dR, dL, kE, &Jp, &Jpu);
    auto fp = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return propagate_point(v, dR, dL, kE);
    };
    auto fpu = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      return propagate_point(p, u(0), u(1), kE);
    };
    EXPECT_LT((Jp - numeric_jacobian(fp, p)).cwiseAbs().maxCoeff(), kTol);
    EXPECT_LT((Jpu - numeric_jacobian(fpu, Eigen::Vector2d(dR, dL))).cwiseAbs().maxCoeff(), kTol);
    // The same motion as eq. (14) in the world: robot at pose, feature at world point.
    const Eigen::Vector3d pose(U(-2, 2), U(-2, 2), U(-kPi, kPi));
    const Eigen::Vector3d pose1 = integrate_pose(pose, dR, dL, kE);
    const Vec2 world = pose.head<2>() + Eigen::Rotation2Dd(pose(2)) * p;
    EXPECT_LT((pose1.head<2>() + Eigen::Rotation2Dd(pose1(2)) * p1 - world).norm(), 1e-12);
    // ... and as eq. (29) up to its discretisation: eq. (29) moves along the heading at the
    // start of the step, eq. (14) along the mid-step heading, an O(d_rho d_theta / 2 +
    // d_rho^2 / D) difference.
    const Vec2 Dt = point_to_distance_form(p);
    const Vec2 Dt1 = point_to_distance_form(p1);
    const Vec2 Dt29 = propagate_feature(Dt, dR, dL, kE);
    const Vec2 st = wheel_step(dR, dL, kE);
    EXPECT_NEAR(Dt1(0), Dt29(0), std::abs(st(0) * st(1)) / 2 + st(0) * st(0) / Dt(0) + 1e-12);

    Mat4 Jf;
    Mat42 Jfu;
    propagate_anchored(f, dR, dL, kE, &Jf, &Jfu);
    auto ff = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return propagate_anchored(v, dR, dL, kE);
    };
    auto ffu = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      return propagate_anchored(f, u(0), u(1), kE);
    };
    EXPECT_LT((Jf - numeric_jacobian(ff, f)).cwiseAbs().maxCoeff(), kTol);
    EXPECT_LT((Jfu - numeric_jacobian(ffu, Eigen::Vector2d(dR, dL))).cwiseAbs().maxCoeff(), kTol);

    Eigen::Matrix<double, 1, 2> Jbp;
    Row3 Jbc;
    predict_bearing_point(p, cam, &Jbp, &Jbc);
    Eigen::VectorXd xpc(5);
    xpc << p, cam;
    auto fb = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return Eigen::VectorXd::Constant(1, predict_bearing_point(v.head<2>(), v.tail<3>()));
    };
    Eigen::Matrix<double, 1, 5> Jb;
    Jb << Jbp, Jbc;
    EXPECT_LT((Jb - numeric_jacobian(fb, xpc, true)).cwiseAbs().maxCoeff(), kTol);

    Row4 Jaf;
    Row3 Jac;
    const double ba = predict_bearing_anchored(f, cam, &Jaf, &Jac);
    EXPECT_NEAR(angle_diff(ba, predict_bearing_point(anchored_to_point(f), cam)), 0.0, 1e-9);
    Eigen::VectorXd xfc(7);
    xfc << f, cam;
    auto fa = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return Eigen::VectorXd::Constant(1, predict_bearing_anchored(v.head<4>(), v.tail<3>()));
    };
    Eigen::Matrix<double, 1, 7> Ja;
    Ja << Jaf, Jac;
    EXPECT_LT((Ja - numeric_jacobian(fa, xfc, true)).cwiseAbs().maxCoeff(), kTol);

    Eigen::Matrix<double, 2, 4> Jpf;
    anchored_to_point(f, &Jpf);
    auto fap = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return anchored_to_point(v); };
    EXPECT_LT((Jpf - numeric_jacobian(fap, f)).cwiseAbs().maxCoeff(), 1e-4);

    Mat2 Jdp;
    const Vec2 dt = point_to_distance_form(p, &Jdp);
    auto fdp = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return point_to_distance_form(v);
    };
    EXPECT_LT((Jdp - numeric_jacobian(fdp, p, false)).cwiseAbs().maxCoeff(), kTol);
    // (D, theta) and the point agree on the bearing (eq. 27 vs atan2 form).
    const Extrinsics ex = extrinsics_from_camera_pose(cam);
    EXPECT_NEAR(
        angle_diff(predict_bearing(dt(0), dt(1), ex), predict_bearing_point(p, cam)), 0, 1e-12);

    Mat3 Jce, Jec;
    const Vec3 c2 = camera_pose_from_extrinsics(ex, &Jce);
    extrinsics_from_camera_pose(cam, &Jec);
    EXPECT_LT((c2 - cam).norm(), 1e-12);
    auto fce = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return camera_pose_from_extrinsics({v(0), v(1), v(2)});
    };
    auto fec = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return extrinsics_from_camera_pose(v).vec();
    };
    EXPECT_LT((Jce - numeric_jacobian(fce, ex.vec(), true)).cwiseAbs().maxCoeff(), kTol);
    EXPECT_LT((Jec - numeric_jacobian(fec, cam, true)).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_LT((Jce * Jec - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Odometry, WheelStepAndChongKleeman) {
  Mat2 J;
  const Vec2 s = wheel_step(0.06, 0.02, 0.5, &J);
  EXPECT_DOUBLE_EQ(s(0), 0.04);
  EXPECT_DOUBLE_EQ(s(1), 0.08);
  const Mat2 Q = chong_kleeman_covariance(0.04, -0.02, 1e-4, 0.0);
  EXPECT_DOUBLE_EQ(Q(0, 0), 4e-6);
  EXPECT_DOUBLE_EQ(Q(1, 1), 2e-6);
  EXPECT_EQ(Q(0, 1), 0.0);
  // Eq. (14): a quarter circle of 4 steps ends where the midpoint rule says.
  Eigen::Vector3d p = integrate_pose(Eigen::Vector3d::Zero(), 0.1, 0.1, 0.5);
  EXPECT_NEAR(p(0), 0.1, 1e-15);
  p = integrate_pose(Eigen::Vector3d::Zero(), 0.25, -0.25, 0.5);  // pure turn of 1 rad
  EXPECT_NEAR(p.head<2>().norm(), 0.0, 1e-15);
  EXPECT_NEAR(p(2), 1.0, 1e-15);
}

// The crossing guard's test: directions within the guard of another, the circle closed at
// +-pi, a chain counted pair by pair, two parts of one line not a crossing.
TEST(CrowdedDirections, FindsTheDirectionsWithANeighbourWithinTheGuard) {
  const double g = deg2rad(1.0);
  const std::vector<std::pair<double, int>> v = {{deg2rad(10.0), 1},
                                                 {deg2rad(10.9), 2},  // a pair
                                                 {deg2rad(50.0), 3},  // alone
                                                 {deg2rad(179.7), 4},
                                                 {deg2rad(-179.8), 5},  // across +-180
                                                 {deg2rad(90.0), 6},
                                                 {deg2rad(90.6), 7},
                                                 {deg2rad(91.2), 8},  // a chain: 6-7, 7-8
                                                 {deg2rad(-30.0), 9},
                                                 {deg2rad(-29.5), 10}};  // one split line
  const std::set<int> out = crowded_directions(
      v, g, [](int a, int b) { return std::min(a, b) == 9 && std::max(a, b) == 10; });
  EXPECT_EQ(out, (std::set<int>{1, 2, 4, 5, 6, 7, 8}));
  EXPECT_EQ(crowded_directions(v, g).count(9), 1u);
  EXPECT_TRUE(crowded_directions(v, 0.0).empty());
  EXPECT_TRUE(crowded_directions({{0.0, 1}}, g).empty());
}

// A frame's motion from its wheel samples (compose_wheel_steps): one step of eq. (14) plus a
// sideways displacement gives the pose the samples give, and so do the filter's two steps
// (frame_steps), a turn in place and a step of eq. (14).
TEST(FrameMotion, ComposedWheelStepsAndTheFiltersTwoStepsGiveThePose) {
  const double e = 0.4;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double max_lateral = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    // A straight that turns within the frame, or random speeds, over 17 samples.
    std::vector<Eigen::Vector2d> travel = {Eigen::Vector2d(u(rng), u(rng))};
    const bool straight_then_turn = trial % 2 == 0;
    const double v = 0.003 * u(rng), w = 0.006 * u(rng);
    for (int i = 0; i < 17; ++i) {
      Eigen::Vector2d d = straight_then_turn
                              ? (i < 9 ? Eigen::Vector2d(v, v) : Eigen::Vector2d(w, -w))
                              : Eigen::Vector2d(0.003 * u(rng), 0.003 * u(rng));
      travel.push_back(travel.back() + d);  // (left, right)
    }
    Eigen::Vector3d direct = Eigen::Vector3d(0.3, -0.2, 0.7);
    const Eigen::Vector3d start = direct;
    for (std::size_t i = 1; i < travel.size(); ++i)
      direct = integrate_pose(
          direct, travel[i](1) - travel[i - 1](1), travel[i](0) - travel[i - 1](0), e);
    const Eigen::Vector3d m = compose_wheel_steps(travel, e);
    const Eigen::Vector3d composed = integrate_pose_lateral(start, m(0), m(1), m(2), e);
    EXPECT_LT((composed - direct).norm(), 1e-12) << "trial " << trial;
    // The total turn is the wheels' (eq. 15).
    const Eigen::Vector2d total = travel.back() - travel.front();
    EXPECT_NEAR((m(0) - m(1)) / e, (total(1) - total(0)) / e, 1e-12);
    const auto steps = frame_steps(m(0), m(1), m(2), e);
    Eigen::Vector3d two = integrate_pose(start, steps[0](0), steps[0](1), e);
    two = integrate_pose(two, steps[1](0), steps[1](1), e);
    if (std::abs(m(2)) <= 0.5 * std::abs(0.5 * (m(0) + m(1)))) {
      EXPECT_LT((two - direct).norm(), 1e-12) << "trial " << trial;
    }
    max_lateral = std::max(max_lateral, std::abs(m(2)));
  }
  EXPECT_GT(max_lateral, 1e-4);  // the test has sideways steps to compose
  // No sideways displacement: one step, as given.
  const auto one = frame_steps(0.02, 0.01, 0.0, e);
  EXPECT_EQ(one[0], Eigen::Vector2d(0.02, 0.01));
  EXPECT_TRUE(one[1].isZero());
}

}  // namespace
}  // namespace omnivert::calib
