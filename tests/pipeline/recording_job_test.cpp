// A recording imported for a job (pipeline/recording_job.hpp): told from a dataset folder,
// written into OUT/dataset with the fixture's images and wheel travel, removed at the end
// unless kept, and nothing left behind by a bad recording.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/pipeline/recording_job.hpp"

namespace omnivert::pipeline {
namespace {

namespace fs = std::filesystem;
const std::string kFx = OMNIVERT_RECORDING_FIXTURES;

class RecordingJob : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_recording_job_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    o.image_topic = "/camera/image_raw";
    o.joint_states_topic = "/joint_states";
    o.left_joint = "wheel_left_joint";
    o.right_joint = "wheel_right_joint";
    o.wheel_radius = 0.1;
    o.wheel_base = 0.5;
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
  recording::ImportOptions o;
};

TEST_F(RecordingJob, RecordingsAreToldFromDatasets) {
  EXPECT_TRUE(is_recording(kFx + "/ros1_lz4.bag"));
  EXPECT_TRUE(is_recording(kFx + "/ros2_zstd.mcap"));
  EXPECT_TRUE(is_recording(kFx + "/ros2_db3"));  // a rosbag2 folder
  fs::create_directories(dir / "ds" / "cam0");
  EXPECT_FALSE(is_recording((dir / "ds").string()));
  EXPECT_FALSE(is_recording((dir / "missing").string()));
}

// The fixture: 5 images, 21 joint states; the wheels at 0.1 m radius run 0.01 and 0.02 m per
// sample.
TEST_F(RecordingJob, ImportsIntoTheOutputFolderAndRemovesIt) {
  const fs::path out = dir / "trk";
  {
    const ImportedDataset d(kFx + "/ros1_lz4.bag", out.string(), o, false);
    EXPECT_EQ(fs::path(d.path()), out / kImportedDatasetDir);
    const auto data = dataset::Dataset::load(d.path());
    EXPECT_EQ(data.size(), 5u);
    ASSERT_EQ(data.wheel().size(), 21u);
    EXPECT_NEAR(data.wheel().back().travel.right, 0.02 * 20, 1e-12);
    EXPECT_EQ(d.summary().images, 5u);
  }
  EXPECT_FALSE(fs::exists(out / kImportedDatasetDir));
  EXPECT_TRUE(fs::exists(out));  // the job's folder stays
  {
    const ImportedDataset d(kFx + "/ros2_zstd.mcap", out.string(), o, true);
    EXPECT_TRUE(d.kept());
  }
  EXPECT_TRUE(fs::exists(out / kImportedDatasetDir / "cam0" / "data.csv"));
  // A kept dataset is replaced by the next import.
  std::ofstream(out / kImportedDatasetDir / "stale.txt") << "x";
  { const ImportedDataset d(kFx + "/ros1_none.bag", out.string(), o, false); }
  EXPECT_FALSE(fs::exists(out / kImportedDatasetDir));
}

TEST_F(RecordingJob, ABadRecordingLeavesNoDataset) {
  o.image_topic = "/nope";
  const fs::path out = dir / "cal";
  EXPECT_THROW(ImportedDataset(kFx + "/ros1_bz2.bag", out.string(), o, true), InputError);
  EXPECT_TRUE(fs::is_empty(out));
}

}  // namespace
}  // namespace omnivert::pipeline
