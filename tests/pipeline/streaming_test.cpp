// pipeline::StreamingCalibrator and `calibrate --streaming` (CalibrateDatasetOptions::streaming)
// on the paper's experiment in the corridor: the estimate within its sigmas of the truth, no
// look-ahead (the estimate after frame k does not depend on the frames after it), the outputs
// and the options refused with it.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "calibration_fixture.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/pipeline/streaming.hpp"

namespace omnivert::testing {
namespace {

using ::testing::HasSubstr;

class Streaming : public CalibrationDatasets {
 protected:
  // The first `frames` images of `data` (all: 0) through a StreamingCalibrator; the estimate
  // after each.
  static std::vector<pipeline::StreamingEstimate> stream(const dataset::Dataset& data,
                                                         std::size_t frames,
                                                         pipeline::StreamingCalibrator* cal) {
    std::vector<pipeline::StreamingEstimate> out;
    const auto& travel = data.travel_at_images();
    const std::size_t n = frames ? frames : data.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::vector<Eigen::Vector2d> wheel =
          i == 0 ? std::vector<Eigen::Vector2d>{{travel[0].left, travel[0].right}}
                 : pipeline::wheel_travel_between_images(data, i);
      out.push_back(cal->add_frame(data.images()[i].timestamp_ns, data.image(i), wheel));
    }
    return out;
  }

  static pipeline::StreamingOptions options_for(const dataset::Dataset& data) {
    pipeline::StreamingOptions o;
    o.calibration = pipeline::options_from_dataset(data, o.calibration);
    return o;
  }
};

TEST_F(Streaming, EstimateIsWithinItsSigmasOfTheTruthAndNeverLooksAhead) {
  const auto data = dataset::Dataset::load(paper().string());
  ASSERT_TRUE(data.ground_truth() && data.ground_truth()->extrinsics);
  const auto& g = *data.ground_truth()->extrinsics;
  const pipeline::StreamingOptions o = options_for(data);
  pipeline::StreamingCalibrator cal(data.camera(), data.wheel_sensor().wheel_base, o);
  const auto all = stream(data, 0, &cal);
  cal.finish();
  ASSERT_EQ(all.size(), data.size());

  // The start-up window holds the prior until the robot has turned, then the filter runs.
  EXPECT_TRUE(all.front().bootstrapping);
  EXPECT_FALSE(all.back().bootstrapping);
  const Eigen::Vector3d prior = o.calibration.prior.mean.vec();
  EXPECT_EQ(all.front().extrinsics.vec(), prior);
  for (const auto& e : all) {
    EXPECT_TRUE(e.described) << "frame " << e.frame << ": " << e.problem;
    EXPECT_TRUE(e.extrinsics.vec().allFinite() && e.covariance.allFinite());
    EXPECT_GE(e.front_end_ms, 0.0);
    EXPECT_GE(e.filter_ms, 0.0);
  }

  // The final estimate: within its sigmas of the truth (NEES under chi-square(3)'s 99.9%), and
  // millimetres from it (docs/validation.md, streaming).
  const Eigen::Vector3d err =
      cal.filter().extrinsics().vec() - Eigen::Vector3d(g.phi, g.rho, g.psi);
  const Eigen::Matrix3d C = cal.filter().covariance();
  const double nees = err.dot(C.ldlt().solve(err));
  EXPECT_LT(nees, 16.27) << "error " << err.transpose() << ", sigmas "
                         << C.diagonal().cwiseSqrt().transpose();
  const calib::Extrinsics truth{g.phi, g.rho, g.psi};
  EXPECT_LT((cal.filter().extrinsics().position() - truth.position()).norm(), 3e-3);

  // No look-ahead: the run cut after frame k gives, after frame k, the same estimate to the bit
  // (frames after the start-up window's, which ends at the turn, frame 76).
  ASSERT_FALSE(all[80].bootstrapping);
  for (std::size_t k : {std::size_t{80}, std::size_t{88}}) {
    SCOPED_TRACE(k);
    pipeline::StreamingCalibrator cut(data.camera(), data.wheel_sensor().wheel_base, o);
    const auto part = stream(data, k + 1, &cut);
    EXPECT_EQ(part.back().extrinsics.vec(), all[k].extrinsics.vec());
    EXPECT_EQ(part.back().covariance, all[k].covariance);
    EXPECT_EQ(part.back().bearings, all[k].bearings);
  }
}

TEST_F(Streaming, CalibrateDatasetWritesTheEstimateOfEveryFrame) {
  const fs::path out = scratch("streaming");
  pipeline::CalibrateDatasetOptions o = cli_defaults();
  o.streaming = true;
  const auto r = pipeline::calibrate_dataset(paper().string(), out.string(), o);
  EXPECT_EQ(r.calibration.source, calib::Estimator::kFilter);
  EXPECT_FALSE(r.calibration.refined);
  EXPECT_FALSE(r.calibration.noise_check.checked);
  EXPECT_THAT(r.streaming_message, HasSubstr("streaming: 93 frames"));
  const std::vector<std::string> rows = read_lines(out / "streaming.csv");
  ASSERT_EQ(rows.size(), 94u);
  EXPECT_THAT(rows.front(), HasSubstr("frame,timestamp_ns,state,phi,rho,psi"));
  // The last row is the filter's estimate after the last frame.
  char phi[64];
  std::snprintf(phi, sizeof phi, ",%.10g,", r.calibration.filter.history.back().extrinsics.phi);
  EXPECT_THAT(rows.back(), HasSubstr(phi));
  const auto json = read_json(out / "summary.json");
  ASSERT_TRUE(json.contains("streaming"));
  EXPECT_EQ(json["streaming"]["frames"].get<int>(), 93);
  EXPECT_GT(json["streaming"]["window_solved_at_frame"].get<int>(), 0);
  EXPECT_GT(json["streaming"]["latency_ms"]["median"].get<double>(), 0.0);
  EXPECT_LE(json["errors_vs_ground_truth"]["filter"]["position_mm"].get<double>(), 3.0);
}

// A frame whose image cannot be read is skipped with a warning naming the file, and the run
// goes on (the batch's FrameSource does the same); streaming.csv still has its row.
TEST_F(Streaming, UnreadableImageIsSkippedWithAWarning) {
  const fs::path data = scratch("streaming-damaged-data");
  copy_dataset(paper(), data);
  const std::string name = image_names(data)[30];
  write_text(data / "cam0/data" / name, "not an image");
  pipeline::CalibrateDatasetOptions o = cli_defaults();
  o.streaming = true;
  const fs::path out = scratch("streaming-damaged");
  const auto r = pipeline::calibrate_dataset(data.string(), out.string(), o);
  EXPECT_EQ(r.frames, 93);
  EXPECT_EQ(r.frames_skipped, 1);
  bool named = false;
  for (const std::string& w : r.warnings) named = named || w.find(name) != std::string::npos;
  EXPECT_TRUE(named) << "no warning names " << name;
  EXPECT_EQ(read_lines(out / "streaming.csv").size(), 94u);
  EXPECT_TRUE(r.calibration.extrinsics.vec().allFinite());
}

TEST_F(Streaming, RefinementAndEarlierTracksAreRefused) {
  pipeline::CalibrateDatasetOptions o = cli_defaults();
  o.streaming = true;
  o.calibration.refinement.enabled = true;
  EXPECT_THAT(input_error_of([&] {
                pipeline::calibrate_dataset(paper().string(), scratch("s-refine").string(), o);
              }),
              HasSubstr("streaming gives the filter's estimate"));
  o.calibration.refinement.enabled = false;
  o.tracks_file = (paper() / "nothing.csv").string();
  EXPECT_THAT(input_error_of([&] {
                pipeline::calibrate_dataset(paper().string(), scratch("s-tracks").string(), o);
              }),
              HasSubstr("streaming needs the images"));
  EXPECT_THROW(
      pipeline::StreamingCalibrator(dataset::Dataset::load(paper().string()).camera(), 0.0, {}),
      InputError);
}

}  // namespace
}  // namespace omnivert::testing
