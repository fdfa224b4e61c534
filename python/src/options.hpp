#pragma once
// The keyword options of the Python calls, one table per options struct of the library, named
// after the command-line flags (`--bearing-sigma` -> bearing_sigma) with the same units and
// the same defaults (the library's presets, which the CLI uses). docs/python.md lists them.

#include "bind.hpp"
#include "omnivert/calib/options.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::python {

// Extraction and descriptor (Sec. 2-3): `omnivert extract`'s flags.
const OptionTable<FeaturePipelineOptions>& extraction_table();
// The tracker (Sec. 4, 9.1): `omnivert track`'s flags but --rules, which picks the base.
const OptionTable<TrackerOptions>& tracker_table();
// The estimator (Sec. 7-8): `omnivert calibrate`'s flags of the filter, refinement, prior and
// models.
const OptionTable<calib::CalibrationOptions>& calibration_table();
// The robot (wheel base, K): given to calibrate() and CalibrationFilter; calibrate_dataset
// reads them from wheel0/sensor.yaml.
const OptionTable<calib::CalibrationOptions>& robot_table();
// calibrate_dataset's own: input checks, output files, time offset, tilt, mask.
const OptionTable<pipeline::CalibrateDatasetOptions>& dataset_job_table();
// track_dataset's own: mask and tilt.
const OptionTable<pipeline::TrackDatasetOptions>& track_job_table();
// The simulator's settings: `omnivert simulate`'s flags.
const OptionTable<sim::SimConfig>& simulation_table();

// The tracker's options: rules="recommended" (recommended_tracker_options(wheel_base), or the
// dataset preset when `for_dataset`) or "paper", then the table's keywords. Removes the keywords
// it used from kwargs.
TrackerOptions tracker_from_kwargs(py::dict& kwargs,
                                   double wheel_base,
                                   bool for_dataset,
                                   const char* call);

// Raises omnivert.InputError "invalid options: <why>" when IsValid refuses them.
template <class O>
void check_valid(const O& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("invalid options: " + why);
}

}  // namespace omnivert::python
