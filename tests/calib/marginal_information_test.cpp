// The marginal information of (phi, rho, psi) on the sparse structure (fast path: each track
// eliminated on its own, then the poses' chain by a sparse LDLT) against the plain reference
// (the whole nuisance block eigen-decomposed), Sec. 8.1: the same verdicts and bounds to 1e-6
// relative, on runs that determine everything and on degenerate ones; where the dense
// reference itself loses digits (a nearly singular marginal), against long double.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/LU>

#include "calib/batch_problem.hpp"
#include "calib/marginal_information.hpp"
#include "calib/synthetic_run.hpp"
#include "omnivert/calib/observability.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::options_for;
using test_support::truth_point;

struct Case {
  std::string name;
  SyntheticRun run;
  CalibrationOptions options;
};

Case make_case(const std::string& name, const SyntheticRunOptions& so) {
  return {name, make_synthetic_run(so), options_for(so)};
}

// Relative difference of two bounds; two infinite bounds agree.
double relative(double a, double b) {
  if (std::isinf(a) && std::isinf(b)) return 0.0;
  return std::abs(a - b) / std::max(std::abs(b), 1e-300);
}

void expect_same_verdict(const ParameterVerdict& fast,
                         const ParameterVerdict& plain,
                         const std::string& what,
                         double tolerance) {
  EXPECT_EQ(fast.determined, plain.determined) << what;
  EXPECT_LT(relative(fast.crlb, plain.crlb), tolerance)
      << what << ": " << fast.crlb << " against " << plain.crlb;
}

// The message without its numbers (the bounds, printed to 6 digits, are compared above).
std::string words(const std::string& m) {
  std::string out;
  for (char ch : m)
    if (!std::isdigit(static_cast<unsigned char>(ch)) && ch != '.' && ch != '-') out += ch;
  return out;
}

// The whole report of both paths: the same verdicts, the bounds to `tolerance` relative.
void expect_same_report(const Case& c, const BatchPoint& at, double tolerance = 1e-6) {
  CalibrationOptions dense = c.options;
  dense.observability.dense_reference = true;
  const ObservabilityReport fast = analyse_observability(c.run.run, c.options, at);
  const ObservabilityReport plain = analyse_observability(c.run.run, dense, at);
  expect_same_verdict(fast.phi, plain.phi, c.name + " phi", tolerance);
  expect_same_verdict(fast.rho, plain.rho, c.name + " rho", tolerance);
  expect_same_verdict(fast.psi, plain.psi, c.name + " psi", tolerance);
  expect_same_verdict(fast.yaw, plain.yaw, c.name + " yaw", tolerance);
  expect_same_verdict(fast.x, plain.x, c.name + " x", tolerance);
  expect_same_verdict(fast.y, plain.y, c.name + " y", tolerance);
  EXPECT_EQ(fast.rank, plain.rank) << c.name;
  EXPECT_LT(relative(fast.condition, plain.condition), 2.0 * tolerance) << c.name;
  // Each eigenvalue of the scaled information, relative to the largest.
  for (int i = 0; i < 3; ++i)
    EXPECT_LT(std::abs(fast.eigenvalues(i) - plain.eigenvalues(i)),
              1e-6 * plain.eigenvalues.maxCoeff())
        << c.name << " eigenvalue " << i;
  EXPECT_EQ(words(fast.message), words(plain.message)) << c.name;
}

// A third reference, for runs where the dense one is itself inaccurate: the exact Schur
// complement of the scaled nuisance block in long double (LU, one step of refinement), without
// pseudo-inverse (runs where no direction is left out).
Eigen::Matrix3d long_double_marginal(const Eigen::MatrixXd& F) {
  using M = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Index n = F.rows(), no = n - 3;
  const M Fl = F.cast<long double>();
  Eigen::Matrix<long double, Eigen::Dynamic, 1> s(no);
  for (Eigen::Index i = 0; i < no; ++i) s(i) = Fl(i, i) > 0 ? 1.0L / std::sqrt(Fl(i, i)) : 1.0L;
  const M Foo = s.asDiagonal() * Fl.topLeftCorner(no, no) * s.asDiagonal();
  const M Foe = s.asDiagonal() * Fl.topRightCorner(no, 3);
  const Eigen::PartialPivLU<M> lu(Foo);
  M X = lu.solve(Foe);
  X += lu.solve(M(Foe - Foo * X));
  const M S = Fl.bottomRightCorner(3, 3) - Foe.transpose() * X;
  return S.cast<double>();
}

TEST(MarginalInformation, SparseEqualsDenseOnDeterminedRuns) {
  for (int seed = 1; seed <= 3; ++seed) {
    SyntheticRunOptions so;
    so.seed = static_cast<std::uint64_t>(seed);
    const Case c = make_case("paper seed " + std::to_string(seed), so);
    expect_same_report(c, truth_point(c.run));
    ASSERT_TRUE(analyse_observability(c.run.run, c.options, truth_point(c.run)).all_determined());
  }
  SyntheticRunOptions zz;
  zz.trajectory = Trajectory::kZigzag;
  zz.seed = 4;
  const Case z = make_case("zigzag", zz);
  expect_same_report(z, truth_point(z.run));
}

// Tracks broken into pieces at the extractor's bearing noise: short tracks seen during the
// turn have little parallax, and the information spans many orders of magnitude (the case
// that needed the Jacobi scaling); and each track with its constant bias as a variable.
TEST(MarginalInformation, SparseEqualsDenseWithShortTracksAndTrackBiases) {
  for (double p : {0.03, 0.1}) {
    SyntheticRunOptions so;
    so.seed = 9;
    so.bearing_sigma = deg2rad(0.025);
    so.break_probability = p;
    const Case c = make_case("broken " + std::to_string(p), so);
    expect_same_report(c, truth_point(c.run));
  }
  SyntheticRunOptions so;
  so.seed = 3;
  so.track_bias_sigma = deg2rad(0.02);
  so.break_probability = 0.05;
  Case c = make_case("biased", so);
  c.options.noise.track_bias_sigma = so.track_bias_sigma;
  expect_same_report(c, truth_point(c.run));
}

// Degenerate runs: a straight line (only phi + psi determined, rank 1), the same at
// 0.005 degree.
TEST(MarginalInformation, SparseEqualsDenseOnDegenerateRuns) {
  SyntheticRunOptions st;
  st.trajectory = Trajectory::kStraight;
  const Case s = make_case("straight", st);
  expect_same_report(s, truth_point(s.run));
  const ObservabilityReport r = analyse_observability(s.run.run, s.options, truth_point(s.run));
  EXPECT_EQ(r.rank, 1);
  EXPECT_TRUE(std::isinf(r.rho.crlb));
  st.bearing_sigma = deg2rad(0.005);
  const Case s5 = make_case("straight 0.005 deg", st);
  expect_same_report(s5, truth_point(s5.run));
}

// A full turn in place after 1 mm of straight: the wheels give no distance, so nothing fixes
// the scale of the camera's circle and of the features around it; psi is determined (0.3
// degree), phi and rho are not (bounds of 9.6 rad and 2 m): the marginal information is
// nearly singular, its small eigenvalues the differences of large numbers. There the dense
// reference is itself off by 8.7e-6 relative (against long double), the sparse path (with its
// refinement step) by 2e-7: the verdicts agree, the bounds to 2e-5 with each other and to 1e-6 with
// the long double reference.
TEST(MarginalInformation, TurnInPlaceAgreesWithTheLongDoubleReference) {
  SyntheticRunOptions rot;
  rot.straight_length = 0.001;
  rot.turn_angle = 2.0 * 3.14159265358979323846;
  const Case t = make_case("turn in place", rot);
  const BatchPoint at = truth_point(t.run);
  expect_same_report(t, at, 2e-5);
  const ObservabilityReport r = analyse_observability(t.run.run, t.options, at);
  EXPECT_TRUE(r.psi.determined);
  EXPECT_FALSE(r.phi.determined || r.rho.determined || r.yaw.determined);
  EXPECT_GT(r.phi.crlb, 1.0);  // [rad]
  EXPECT_GT(r.rho.crlb, 1.0);  // [m]
  internal::Built b = internal::build(t.run.run, t.options, at, false);
  const Eigen::SparseMatrix<double> F = internal::fisher_information(b);
  const Eigen::Matrix3d exact = long_double_marginal(Eigen::MatrixXd(F)).inverse();
  const Eigen::Matrix3d fast =
      internal::marginal_information_sparse(F, internal::layout_of(b)).inverse();
  const Eigen::Matrix3d plain = internal::marginal_information_dense(Eigen::MatrixXd(F)).inverse();
  double worst_fast = 0.0, worst_plain = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double e = std::sqrt(exact(i, i));
    worst_fast = std::max(worst_fast, relative(std::sqrt(fast(i, i)), e));
    worst_plain = std::max(worst_plain, relative(std::sqrt(plain(i, i)), e));
  }
  EXPECT_LT(worst_fast, 1e-6);
  EXPECT_GT(worst_plain, 1e-6);  // the reference's own error, which the tolerance above allows
  RecordProperty("sparse_relative_error", std::to_string(worst_fast));
  RecordProperty("dense_relative_error", std::to_string(worst_plain));
}

// A feature straight ahead of a straight run: its bearing never changes, the derivative along
// its ray is exactly zero at every pose, and both paths leave that direction out (the
// pseudo-inverse); a plain inverse would be singular.
TEST(MarginalInformation, FeatureWithoutParallaxIsLeftOutByBothPaths) {
  SyntheticRunOptions st;
  st.trajectory = Trajectory::kStraight;
  Case c = make_case("ahead", st);
  const Extrinsics& ex = c.run.truth;
  const Eigen::Vector2d ahead(20.0, ex.rho * std::sin(ex.phi));  // on the camera's line
  const int id = 1000;
  for (std::size_t k = 0; k < c.run.run.frames.size(); ++k)
    c.run.run.frames[k].observations.push_back(
        {id, bearing_from_geometry(c.run.true_poses[k], ahead, ex)});
  BatchPoint at = truth_point(c.run);
  at.features[id] = ahead;
  expect_same_report(c, at);
  internal::Built b = internal::build(c.run.run, c.options, at, false);
  internal::SparseMarginalStats stats;
  internal::marginal_information_sparse(
      internal::fisher_information(b), internal::layout_of(b), &stats);
  EXPECT_TRUE(stats.ok);
  EXPECT_EQ(stats.dropped_directions, 1);
}

// The matrices themselves on a determined run, and the layout's columns.
TEST(MarginalInformation, MatricesAgreeAndTheLayoutCoversEveryColumn) {
  SyntheticRunOptions so;
  so.seed = 5;
  so.break_probability = 0.05;
  so.track_bias_sigma = deg2rad(0.02);
  Case c = make_case("matrices", so);
  c.options.noise.track_bias_sigma = so.track_bias_sigma;
  internal::Built b = internal::build(c.run.run, c.options, truth_point(c.run), false);
  const Eigen::SparseMatrix<double> F = internal::fisher_information(b);
  const internal::VariableLayout l = internal::layout_of(b);
  int columns = l.num_pose_columns + 3;
  for (const auto& t : l.track_columns) {
    EXPECT_EQ(t.size(), 3u);  // point and bias
    columns += static_cast<int>(t.size());
  }
  EXPECT_EQ(columns, F.cols());
  internal::SparseMarginalStats stats;
  const Eigen::Matrix3d fast = internal::marginal_information_sparse(F, l, &stats);
  const Eigen::Matrix3d plain = internal::marginal_information_dense(Eigen::MatrixXd(F));
  ASSERT_TRUE(stats.ok);
  EXPECT_EQ(stats.dropped_directions, 0);
  EXPECT_GT(stats.nuisance_lambda_max, 1.0);  // unit diagonal, coupled variables
  const Eigen::Matrix3d exact = long_double_marginal(Eigen::MatrixXd(F));
  const Eigen::Matrix3d fi = fast.inverse(), pi = plain.inverse(), ei = exact.inverse();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(fast(i, j), plain(i, j), 1e-8 * plain.norm()) << i << "," << j;
      EXPECT_NEAR(fast(i, j), exact(i, j), 1e-9 * exact.norm()) << i << "," << j;
      EXPECT_NEAR(fi(i, j), pi(i, j), 1e-7 * std::sqrt(pi(i, i) * pi(j, j))) << i << "," << j;
      EXPECT_NEAR(fi(i, j), ei(i, j), 1e-7 * std::sqrt(ei(i, i) * ei(j, j))) << i << "," << j;
    }
}

}  // namespace
}  // namespace omnivert::calib
