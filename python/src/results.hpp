#pragma once
// The calibration result as Python sees it (calib.cpp binds it; pipeline.cpp returns it
// inside the dataset job's result): the library's CalibrationResult with the options it was
// computed with and the truth when known, which its summary reports.

#include <optional>
#include <vector>

#include "bind.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert::python {

struct Calibration {
  calib::CalibrationResult result;
  calib::CalibrationOptions options;
  std::optional<calib::Extrinsics> truth;
};

// states.csv's columns as numpy arrays (frame, phi, rho, psi, sigma_phi, sigma_rho,
// sigma_psi, features, updates, rejected, new, guarded).
py::dict history_dict(const std::vector<calib::FrameEstimate>& history);

// The tracker's counters (TrackerStats) as a dict (tracking.cpp).
py::dict stats_dict(const TrackerStats& stats);

}  // namespace omnivert::python
