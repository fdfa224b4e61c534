#pragma once
// refine_batch with its steps chosen by the caller, for calibrate()'s scheduling.

#include <functional>

#include "omnivert/calib/refinement.hpp"

namespace omnivert::calib::internal {

struct RefineSteps {
  // Called once the first solve is done. That solve holds the refinement's largest problem
  // (every bearing, before the crossing guard and the association remove some); calibrate()
  // starts the filter's noise check beside the refinement only then, so that the two runs'
  // largest problems are never in memory at once.
  std::function<void()> after_first_solve;
  // The covariance of (phi, rho, psi) at the solution; the filter's noise check, which keeps
  // only RefinementResult::noise, goes without it (then covariance_ok is false).
  bool covariance = true;
};

// refine_batch, with `steps`.
RefinementResult refine_batch(const CalibrationRun& run,
                              const CalibrationOptions& options,
                              const BatchPoint& start,
                              const RefineSteps& steps);

}  // namespace omnivert::calib::internal
