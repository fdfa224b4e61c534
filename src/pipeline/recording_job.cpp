#include "omnivert/pipeline/recording_job.hpp"

#include <filesystem>
#include <memory>

#include "omnivert/core/error.hpp"

namespace omnivert::pipeline {

namespace fs = std::filesystem;

bool is_recording(const std::string& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return true;
  if (!fs::is_directory(path, ec) || fs::exists(fs::path(path) / "cam0", ec)) return false;
  if (fs::exists(fs::path(path) / "metadata.yaml", ec)) return true;
  for (const auto& e : fs::directory_iterator(path, ec)) {
    const auto ext = e.path().extension();
    if (ext == ".db3" || ext == ".mcap") return true;
  }
  return false;
}

ImportedDataset::ImportedDataset(const std::string& recording_path,
                                 const std::string& out_dir,
                                 recording::ImportOptions options,
                                 bool keep)
    : recording_(recording_path), keep_(keep) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw InputError(out_dir, 0, "cannot create the output folder: " + ec.message());
  path_ = (fs::path(out_dir) / kImportedDatasetDir).string();
  options.out = path_;
  options.overwrite = true;  // the job's own folder: an earlier kept import is replaced
  const std::unique_ptr<recording::Recording> rec = recording::open_recording(recording_path);
  summary_ = recording::import_recording(*rec, options);
}

ImportedDataset::~ImportedDataset() {
  std::error_code ec;
  if (!keep_ && !path_.empty()) fs::remove_all(path_, ec);
}

}  // namespace omnivert::pipeline
