#pragma once
// The calibration tests' datasets and helpers: the paper's experiment in the corridor (93
// frames, observable) and a straight-only run (45 frames, not observable), as
// `omnivert simulate --world corridor --trajectory paper --seed 2` and
// `... --trajectory straight --frames 45 --seed 2` render them.

#include <string>
#include <utility>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "omnivert/core/error.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "simulated_datasets.hpp"

namespace omnivert::testing {

class CalibrationDatasets : public SimulatedDatasets {
 protected:
  static fs::path paper() { return dataset("paper", {"corridor", "paper", 2, 0}); }
  static fs::path straight() { return dataset("straight", {"corridor", "straight", 2, 45}); }
};

// The options `omnivert calibrate DATASET --out DIR` passes without flags
// (tools/cmd_calibrate.cpp): the library's defaults (the recommended tracker with the odometry
// gate on, its wheel base from wheel0/sensor.yaml; the recommended calibration options).
inline pipeline::CalibrateDatasetOptions cli_defaults() { return {}; }

inline pipeline::CalibrateDatasetOptions cli_defaults_refined() {
  pipeline::CalibrateDatasetOptions o = cli_defaults();
  o.calibration.refinement.enabled = true;
  return o;
}

// The message of the InputError that `run` throws; a test failure when it throws none.
template <class F>
std::string input_error_of(F&& run) {
  try {
    std::forward<F>(run)();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}

}  // namespace omnivert::testing
