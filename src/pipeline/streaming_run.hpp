#pragma once
// `omnivert calibrate --streaming` (CalibrateDatasetOptions::streaming): a dataset's images
// fed one by one to a StreamingCalibrator, in order, on one thread, and what the run's
// outputs need of it.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "omnivert/pipeline/streaming.hpp"
#include "omnivert/pipeline/track_dataset.hpp"

namespace omnivert::pipeline::internal {

struct StreamedRun {
  TrackDatasetResult tracked;  // the tracks.csv rows, frames, skipped frames, warnings
  DatasetRun input;            // the filter's input, frame by frame
  calib::FilterResult filter;
  std::vector<StreamingEstimate> estimates;  // one per frame
};

// `opt`: the calibration options with the dataset's wheel base and K (options_from_dataset).
StreamedRun stream_dataset(const dataset::Dataset& data,
                           const CalibrateDatasetOptions& o,
                           const calib::CalibrationOptions& opt);

// streaming.csv (docs/outputs.md), written atomically.
void write_streaming_csv(const std::string& path, const std::vector<StreamingEstimate>& estimates);

// summary.json's "streaming" object (JSON text) and report.html's section: frames, when the
// start-up window was solved, time per frame (median, 95th percentile, largest) in all and per
// stage.
std::string streaming_json(const std::vector<StreamingEstimate>& estimates);
std::string streaming_html(const std::vector<StreamingEstimate>& estimates);
// The terminal's line on the times.
std::string streaming_line(const std::vector<StreamingEstimate>& estimates);

}  // namespace omnivert::pipeline::internal
