#pragma once
// The calibration's convergence picture (paper Fig. 25).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/calib/calibration_filter.hpp"

namespace omnivert::viz {

// Fig. 25: two rows of three plots (phi [deg], rho [mm], psi [deg]; their sigmas), against
// the frame number, with +-3 sigma dashed around the estimate, the truth and the refined
// value (when given) as horizontal lines.
cv::Mat draw_convergence(const std::vector<calib::FrameEstimate>& history,
                         const std::optional<calib::Extrinsics>& truth = std::nullopt,
                         const std::optional<calib::Extrinsics>& refined = std::nullopt);

}  // namespace omnivert::viz
