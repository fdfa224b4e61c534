#pragma once
// `track` and `calibrate` on a robot's recording (docs/import.md#track-and-calibrate-a-recording):
// the recording is imported as a dataset (omnivert/recording/import.hpp) into the folder
// `dataset/` inside the job's output folder, the job reads it like any dataset folder, and the
// folder is removed when the job ends unless it is to be kept (to run the job again with other
// options without importing again, or to look at the images).
//
// Why there: the images of a long recording take gigabytes, which the output folder's disk is
// known to take, and a temporary folder (/tmp, often a small RAM disk) is not; a kept dataset
// is found where the results are.

#include <string>

#include "omnivert/recording/import.hpp"

namespace omnivert::pipeline {

// Whether `path` is a recording (a ROS 1 bag, a ROS 2 .db3 or .mcap file, a ROS 2 bag folder
// with metadata.yaml or one .db3 or .mcap file) rather than a dataset folder (cam0/).
bool is_recording(const std::string& path);

// The imported dataset's folder inside the job's output folder.
inline constexpr const char* kImportedDatasetDir = "dataset";

class ImportedDataset {
 public:
  // Imports `recording_path` into `out_dir`/dataset (created; an earlier one there is
  // replaced): options.out and options.overwrite are set here. Throws InputError as
  // import_recording does, leaving no dataset.
  ImportedDataset(const std::string& recording_path,
                  const std::string& out_dir,
                  recording::ImportOptions options,
                  bool keep);
  // Removes the dataset unless kept.
  ~ImportedDataset();
  ImportedDataset(const ImportedDataset&) = delete;
  ImportedDataset& operator=(const ImportedDataset&) = delete;

  const std::string& recording() const { return recording_; }
  const std::string& path() const { return path_; }
  const recording::ImportSummary& summary() const { return summary_; }
  bool kept() const { return keep_; }

 private:
  std::string recording_, path_;
  recording::ImportSummary summary_;
  bool keep_ = false;
};

}  // namespace omnivert::pipeline
