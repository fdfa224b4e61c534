#pragma once
// refine_batch with its steps chosen by the caller.

#include "omnivert/calib/refinement.hpp"

namespace omnivert::calib::internal {

struct RefineSteps {
  // The covariance of (phi, rho, psi) at the solution; the filter's noise check, which keeps
  // only RefinementResult::noise, goes without it (then covariance_ok is false and the time
  // offset's sigma NaN).
  bool covariance = true;
};

// refine_batch, with `steps`.
RefinementResult refine_batch(const CalibrationRun& run,
                              const CalibrationOptions& options,
                              const BatchPoint& start,
                              const RefineSteps& steps);

}  // namespace omnivert::calib::internal
