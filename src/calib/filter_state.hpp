#pragma once
// The state of the self-calibration EKF, eq. (28):
//   X = [D^1, theta^1, ..., D^Z, theta^Z, phi, rho, psi]
// with its covariance P. Features come first (in the order they entered), the extrinsics are
// the last three entries. Features enter when their track starts and are marginalised out
// (their rows and columns dropped) when it ends.
//
// Each feature block has a parametrisation (FeatureParam): the paper's (D, theta); the
// inverse distance (q = 1/D, theta); a robot-frame point (p_x, p_y); an anchored inverse-depth
// point (a_x, a_y, alpha, q) (see model.hpp). The extrinsics block is either the paper's
// (phi, rho, psi) or the camera pose (c_x, c_y, eta = phi + psi) (ExtrinsicsParam); the
// accessors always answer in (phi, rho, psi) and (D, theta).

#include <Eigen/Core>
#include <vector>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

enum class FeatureParam { kDistance, kInverseDistance, kPoint, kAnchored };
enum class ExtrinsicsParam { kPaper, kCameraPose };

int feature_param_size(FeatureParam p);

struct FeatureSlot {
  int track_id = -1;
  FeatureParam param = FeatureParam::kDistance;
  int index = 0;  // first entry in x (kept up to date by FilterState)
  int size = 2;
  int first_frame = 0;
  int last_seen_frame = 0;
  int num_updates = 0;
  // CalibrationOptions::noise.track_bias_sigma > 0: the block ends with one more entry, the track's
  // constant bearing error b (each bearing is eq. (30) + b); size is then feature_param_size + 1.
  bool bias = false;
  // Index in x of b (bias only).
  int bias_index() const { return index + size - 1; }
};

class FilterState {
 public:
  // The prior is given in (phi, rho, psi); with kCameraPose it is carried to (c_x, c_y, eta)
  // through the Jacobian of the map at the prior mean.
  FilterState(const Extrinsics& prior,
              const Eigen::Vector3d& prior_sigma,
              ExtrinsicsParam param = ExtrinsicsParam::kPaper);

  int dim() const { return static_cast<int>(x_.size()); }
  int num_features() const { return static_cast<int>(slots_.size()); }
  int extrinsics_index() const { return dim() - 3; }
  ExtrinsicsParam extrinsics_param() const { return ext_param_; }
  // Slot of a track, -1 if the track is not in the state.
  int find(int track_id) const;

  Extrinsics extrinsics() const;
  Eigen::Matrix3d extrinsics_covariance() const;  // of (phi, rho, psi)
  // Feature block as (D, theta) whatever its parametrisation, with its 2x2 covariance.
  Eigen::Vector2d feature_distance_form(int slot, Eigen::Matrix2d* cov = nullptr) const;

  const Eigen::VectorXd& x() const { return x_; }
  const Eigen::MatrixXd& P() const { return P_; }
  Eigen::VectorXd& mutable_x() { return x_; }
  Eigen::MatrixXd& mutable_P() { return P_; }
  const std::vector<FeatureSlot>& slots() const { return slots_; }
  std::vector<FeatureSlot>& mutable_slots() { return slots_; }

  // Stochastic augmentation: appends a feature block with value xf, covariance P_ff and
  // cross-covariance P_fx (size x dim(), against the current state).
  void add_feature(FeatureSlot slot,
                   const Eigen::VectorXd& xf,
                   const Eigen::MatrixXd& P_fx,
                   const Eigen::MatrixXd& P_ff);
  // Marginalisation: removes the feature's rows and columns.
  void remove_feature(int slot);
  // Changes a block's parametrisation: x_block <- y (new size m), P <- T P T^T with T the
  // identity except J (m x the parametrisation's size) on the block; a track's bias entry
  // (FeatureSlot::bias) is kept as it is.
  void reparametrise(int slot,
                     FeatureParam param,
                     const Eigen::VectorXd& y,
                     const Eigen::MatrixXd& J);
  // Keeps angles in (-pi, pi] and P symmetric; keeps distances positive.
  void normalise();
  // Replaces the whole state (used by the bootstrap window); slots' index/size are recomputed.
  void reset(const Eigen::VectorXd& x, const Eigen::MatrixXd& P, std::vector<FeatureSlot> slots);

 private:
  void reindex();
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  std::vector<FeatureSlot> slots_;
  ExtrinsicsParam ext_param_;
};

}  // namespace omnivert::calib
