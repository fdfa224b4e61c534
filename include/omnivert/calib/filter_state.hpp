#pragma once
// The state of the self-calibration EKF, eq. (28):
//   X = [D^1, theta^1, ..., D^Z, theta^Z, phi, rho, psi]
// with its covariance P. Features come first (two entries each, in the order they entered),
// the extrinsics are the last three entries. A feature block is either (D, theta) of eq. (28)
// or, while its distance is still poorly known, (q = 1/D, theta) (see FeatureInit).
// Features enter when their track starts and are marginalised out (their rows and columns
// dropped) when it ends.

#include <Eigen/Core>
#include <vector>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

enum class FeatureParam { kDistance, kInverseDistance };

struct FeatureSlot {
  int track_id = -1;
  FeatureParam param = FeatureParam::kDistance;
  int first_frame = 0;
  int last_seen_frame = 0;
  int num_updates = 0;
};

class FilterState {
 public:
  FilterState(const Extrinsics& prior, const Eigen::Vector3d& prior_sigma);

  int dim() const { return static_cast<int>(x_.size()); }
  int num_features() const { return static_cast<int>(slots_.size()); }
  // Index in x of feature slot i (its first entry) and of phi (rho, psi follow).
  static int feature_index(int slot) { return 2 * slot; }
  int extrinsics_index() const { return dim() - 3; }
  // Slot of a track, -1 if the track is not in the state.
  int find(int track_id) const;

  Extrinsics extrinsics() const;
  Eigen::Matrix3d extrinsics_covariance() const;
  // Feature block as (D, theta) whatever its parametrisation, with its 2x2 covariance.
  Eigen::Vector2d feature_distance_form(int slot, Eigen::Matrix2d* cov = nullptr) const;

  const Eigen::VectorXd& x() const { return x_; }
  const Eigen::MatrixXd& P() const { return P_; }
  Eigen::VectorXd& mutable_x() { return x_; }
  Eigen::MatrixXd& mutable_P() { return P_; }
  const std::vector<FeatureSlot>& slots() const { return slots_; }
  std::vector<FeatureSlot>& mutable_slots() { return slots_; }

  // Stochastic augmentation: appends feature `slot` with value xf, covariance P_ff and
  // cross-covariance P_fx (2 x dim(), against the current state).
  void add_feature(const FeatureSlot& slot, const Eigen::Vector2d& xf,
                   const Eigen::Matrix<double, 2, Eigen::Dynamic>& P_fx,
                   const Eigen::Matrix2d& P_ff);
  // Marginalisation: removes the feature's rows and columns.
  void remove_feature(int slot);
  // Changes a (q, theta) block to (D, theta): x and P through J = diag(-1/q^2, 1).
  void convert_to_distance(int slot);
  // Keeps angles in (-pi, pi] and P symmetric; keeps q and D positive.
  void normalise();

 private:
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  std::vector<FeatureSlot> slots_;
};

}  // namespace omnivert::calib
