// The tilt check of a dataset (pipeline/tilt_check.hpp, docs/theory/tilt.md#estimate) on a
// rendered run whose mirror axis leans 2 degrees towards the camera bearing 40 degrees: the
// second pass, measured on frames rectified with the first, lands nearer the truth than the
// first; a given tilt is used as it is and not measured.

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "omnivert/pipeline/tilt_check.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "simulated_datasets.hpp"

namespace omnivert::testing {
namespace {

class TiltCheck : public SimulatedDatasets {
 protected:
  static constexpr double kTiltDeg = 2.0, kDirectionDeg = 40.0;

  static const fs::path& tilted_dir() {
    static const fs::path dir = [] {
      sim::SimConfig cfg;
      cfg.seed = 3;  // the whole paper run: its first frames see few lines, from one place
      cfg.camera.tilt_deg = kTiltDeg;
      cfg.camera.tilt_direction_deg = kDirectionDeg;
      const fs::path d = scratch("tilted");
      sim::simulate(sim::load_world("office"), sim::load_trajectory("paper"), cfg, d.string());
      return d;
    }();
    return dir;
  }

  static const dataset::Dataset& tilted() {
    static const dataset::Dataset data = [] {
      dataset::LoadOptions lo;
      lo.require_wheel = false;
      return dataset::Dataset::load(tilted_dir().string(), lo);
    }();
    return data;
  }

  // Distance of a tilt vector from the truth [deg] (the tilt vector's error: both the size and
  // the direction of the lean).
  static double error_deg(const Eigen::Vector2d& v) {
    pipeline::TiltCheckOptions truth;
    truth.given_deg = kTiltDeg;
    truth.given_direction_deg = kDirectionDeg;
    return rad2deg((v - truth.given_vector()).norm());
  }
};

// The second pass corrects what the first got wrong: here an estimator that counts only the
// pixels within 1 px of each line's curve (4.5 px at the start by default) keeps, from x = 0,
// the pixels of the curved verticals nearest their radial fits, and the first pass measures
// too small a tilt; on the rectified frames the verticals are radial again.
TEST_F(TiltCheck, SecondPassCorrectsTheFirst) {
  pipeline::TiltCheckOptions one, two;
  one.estimator.corridor_px = two.estimator.corridor_px = 1.0;
  one.passes = 1;
  two.passes = 2;
  const TiltEstimate first = pipeline::measure_tilt(tilted(), FeaturePipelineOptions{}, one);
  const TiltEstimate second = pipeline::measure_tilt(tilted(), FeaturePipelineOptions{}, two);
  ASSERT_TRUE(first.valid);
  ASSERT_TRUE(second.valid);
  std::printf("first pass: %s (error %.3f deg)\nsecond pass: %s (error %.3f deg)\n",
              first.describe().c_str(),
              error_deg(first.vector),
              second.describe().c_str(),
              error_deg(second.vector));
  EXPECT_GT(error_deg(first.vector), 0.1);
  EXPECT_LT(error_deg(second.vector), 0.05);
}

TEST_F(TiltCheck, BothPassesAtTheDefaultsWithinATenthOfADegree) {
  pipeline::TiltCheckOptions one, two;
  one.passes = 1;
  two.passes = 2;
  const TiltEstimate first = pipeline::measure_tilt(tilted(), FeaturePipelineOptions{}, one);
  const TiltEstimate second = pipeline::measure_tilt(tilted(), FeaturePipelineOptions{}, two);
  ASSERT_TRUE(first.valid && second.valid);
  std::printf("defaults: first pass error %.3f deg, second %.3f deg\n",
              error_deg(first.vector),
              error_deg(second.vector));
  EXPECT_LT(error_deg(first.vector), 0.1);
  EXPECT_LT(error_deg(second.vector), 0.05);
}

TEST_F(TiltCheck, GivenTiltIsUsedAndNotMeasured) {
  pipeline::TrackDatasetOptions o;
  o.tilt.given_deg = kTiltDeg;
  o.tilt.given_direction_deg = kDirectionDeg;
  const pipeline::TrackDatasetResult r = pipeline::track_dataset(tilted(), o);
  EXPECT_FALSE(r.tilt.valid);  // not a measurement
  EXPECT_TRUE(r.tilt_corrected);
  EXPECT_NEAR(r.tilt.tilt_deg(), kTiltDeg, 1e-12);
  EXPECT_NEAR(r.tilt.direction_deg(), kDirectionDeg, 1e-12);
  EXPECT_EQ(pipeline::tilt_line(r.tilt, r.tilt_corrected),
            "frames rectified with the given tilt, 2.00 deg towards bearing 40.0 deg");
  EXPECT_GT(r.rows.size(), 200u);
}

// Streaming looks at no later frame: the tilt is measured on the first image, and the frames
// rectified with it.
TEST_F(TiltCheck, StreamingRectifiesWithTheFirstImagesTilt) {
  pipeline::CalibrateDatasetOptions o;
  o.streaming = true;
  o.calibration.refinement.enabled = false;
  const fs::path out = scratch("streamed");
  const auto r = pipeline::calibrate_dataset(tilted_dir().string(), out.string(), o);
  ASSERT_TRUE(r.tilt.valid);
  // The tilt in summary.json and in the report.
  const auto summary = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(summary["inputs"]["tilt"]["source"], "measured");
  EXPECT_EQ(summary["inputs"]["tilt"]["frames"], 1);
  EXPECT_TRUE(summary["inputs"]["tilt"]["rectified"].get<bool>());
  EXPECT_NEAR(summary["inputs"]["tilt"]["tilt_deg"].get<double>(), kTiltDeg, 0.2);
  EXPECT_NE(read_text(out / "report.html").find("frames rectified"), std::string::npos);
  EXPECT_EQ(r.tilt.frames, 1);
  EXPECT_TRUE(r.tilt_corrected);
  EXPECT_LT(error_deg(r.tilt.vector), 0.2);
  ASSERT_TRUE(r.truth.has_value());
  o.tilt.correct_deg = 90.0;  // the frames as they are
  const auto raw = pipeline::calibrate_dataset(tilted_dir().string(), scratch("raw").string(), o);
  EXPECT_FALSE(raw.tilt_corrected);
  auto off_mm = [&](const pipeline::CalibrateDatasetResult& x) {
    return (x.calibration.extrinsics.position() - x.truth->position()).norm() * 1e3;
  };
  std::printf(
      "streaming: camera %.2f mm from the truth rectified, %.2f mm raw\n", off_mm(r), off_mm(raw));
  EXPECT_LT(off_mm(r), 3.0);
  EXPECT_GT(off_mm(raw), 2.0 * off_mm(r));
}

TEST_F(TiltCheck, GivenTiltOutsideItsRangeIsRefused) {
  pipeline::TiltCheckOptions o;
  std::string why;
  o.given_deg = 30.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("given tilt"), std::string::npos) << why;
  o.given_deg = 1.0;
  o.given_direction_deg = NAN;
  EXPECT_FALSE(o.IsValid(&why));
  o.given_direction_deg = 10.0;
  o.passes = 0;
  EXPECT_FALSE(o.IsValid(&why));
}

}  // namespace
}  // namespace omnivert::testing
