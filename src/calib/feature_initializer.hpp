#pragma once
// How a new track enters the state (the paper leaves it open; docs/theory/filter.md shows it
// decides the outcome). Both methods are a stochastic augmentation y = g(x_ext, beta, prior): the
// new block gets P_yy = G_x P_xx G_x^T + G_n N G_n^T and P_yx = G_x P_x., so it is correlated
// with the extrinsics it was computed from.
//   kNaive: D = D0 +- sigma_D0, theta = pi - beta - phi - psi (far-feature eq. 25).
//   kInverseDistance: the feature on the camera ray of beta at inverse distance q_c from
//     the camera, q_c ~ N(q0, sigma_q^2) spanning [1/max_distance, 1/min_distance] at
//     two sigma; stored as (q = 1/D, theta) of the robot origin.

#include "calib/filter_state.hpp"
#include "omnivert/calib/options.hpp"

namespace omnivert::calib {

class FeatureInitializer {
 public:
  explicit FeatureInitializer(const CalibrationOptions& options) : options_(options) {}
  // Adds track `track_id`, first seen at bearing beta (sigma:
  // CalibrationOptions::noise.bearing_sigma x sigma_scale) in frame `frame`. Returns its slot.
  int initialize(
      int track_id, double beta, int frame, FilterState* state, double sigma_scale = 1.0) const;

 private:
  CalibrationOptions options_;
};

}  // namespace omnivert::calib
