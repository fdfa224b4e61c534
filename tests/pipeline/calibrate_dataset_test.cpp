// pipeline::calibrate_dataset, the main job, on simulated datasets: the paper's experiment
// end to end within its tolerances, the noise check, the noise model's options, the
// observability verdict of a straight-only run, the prior, earlier tracks, crowded lines and
// the few-tracks warning. Damaged datasets: calibrate_damaged_dataset_test.cpp.

#include <cmath>
#include <regex>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "calibration_fixture.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/pipeline/calibration_report.hpp"

namespace omnivert::testing {
namespace {

using pipeline::calibrate_dataset;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;

class CalibrateDataset : public CalibrationDatasets {};

TEST_F(CalibrateDataset, PaperRunWithRefinementIsWithinToleranceOfTheTruth) {
  const fs::path out = scratch("paper-refined");
  const auto r = calibrate_dataset(paper().string(), out.string(), cli_defaults_refined());
  expect_complete_outputs_without_nan(out);
  ASSERT_TRUE(r.wrote_extrinsics);
  EXPECT_TRUE(r.calibration.observable());
  ASSERT_TRUE(r.truth.has_value());

  const std::string yaml = read_text(out / "extrinsics.yaml");
  for (const char* key : {"phi",
                          "rho",
                          "psi",
                          "sigma_phi",
                          "sigma_rho",
                          "sigma_psi",
                          "covariance",
                          "x",
                          "y",
                          "yaw",
                          "T_base_cam",
                          "observable",
                          "crlb_phi",
                          "crlb_rho",
                          "crlb_psi"})
    EXPECT_TRUE(std::regex_search(yaml, std::regex(std::string("(^|\n)") + key + ":")))
        << "extrinsics.yaml has no key " << key;
  EXPECT_THAT(yaml, HasSubstr("\nobservable: true"));

  // The paper's experiment from pixels: within a few sigma of the truth, both estimates.
  const auto json = read_json(out / "summary.json");
  for (const char* estimate : {"filter", "refinement"}) {
    SCOPED_TRACE(estimate);
    const auto& e = json["errors_vs_ground_truth"][estimate];
    EXPECT_LE(e["position_mm"].get<double>(), 5.0);
    EXPECT_LE(std::abs(e["yaw_deg"].get<double>()), 0.3);
    EXPECT_LE(e["nees"].get<double>(), 16.3);
  }
  EXPECT_EQ(json["result"]["source"], "refinement");
  EXPECT_TRUE(r.calibration.refined && r.calibration.refinement.covariance_ok);
  EXPECT_EQ(r.extrinsics().phi, r.calibration.refinement.extrinsics.phi);
  EXPECT_THAT(r.BriefReport(), HasSubstr("error vs ground truth (refinement)"));
}

// A copy of `from` whose image stamps are late by shift_ns, the first and last image left out
// (so that every shifted image stays inside the wheel data) and ground_truth/ holding only
// extrinsics.yaml (its lines.csv names the old stamps; scripts/eval-time-offset).
fs::path shifted_copy(const fs::path& from, const fs::path& to, long long shift_ns) {
  copy_dataset(from, to);
  for (const auto& f : fs::directory_iterator(to / "ground_truth"))
    if (f.path().filename() != "extrinsics.yaml") fs::remove_all(f.path());
  std::vector<std::string> rows, out;
  for (const std::string& row : read_lines(from / "cam0/data.csv"))
    (row.empty() || row[0] == '#' ? out : rows).push_back(row);
  for (std::size_t i = 1; i + 1 < rows.size(); ++i) {
    const std::size_t comma = rows[i].find(',');
    out.push_back(std::to_string(std::stoll(rows[i].substr(0, comma)) + shift_ns) +
                  rows[i].substr(comma));
  }
  write_lines(to / "cam0/data.csv", out);
  return to;
}

// docs/calibration.md#time-offset: the paper run has one change of motion (the straight
// ending in the turn in place), too few for the tracks' estimate to be applied (its jackknife
// sigma is hundreds of ms); the refinement finds the 80 ms with the extrinsics, and the run is
// tracked and calibrated again on stamps corrected by it: the same answer as the synchronised
// copy's, which is not tracked again.
TEST_F(CalibrateDataset, AnOffsetTheRefinementFindsIsAppliedAndTheRunTrackedAgain) {
  const auto sync = calibrate_dataset(shifted_copy(paper(), scratch("sync"), 0).string(),
                                      scratch("sync-out").string(),
                                      cli_defaults_refined());
  const auto late = calibrate_dataset(shifted_copy(paper(), scratch("late"), 80'000'000).string(),
                                      scratch("late-out").string(),
                                      cli_defaults_refined());
  ASSERT_TRUE(sync.truth && late.truth);
  EXPECT_FALSE(sync.time_offset.retracked);
  EXPECT_FALSE(sync.time_offset_applied);
  EXPECT_NEAR(sync.time_offset.offset_s, 0.0, std::max(3 * sync.time_offset.sigma_s, 0.005));

  const pipeline::TimeOffsetEstimate& e = late.time_offset;
  EXPECT_TRUE(e.refined && e.retracked && late.time_offset_applied);
  EXPECT_FALSE(e.tracks_applied) << e.tracks_offset_s << " +- " << e.tracks_sigma_s;
  EXPECT_NEAR(e.retracked_s, 0.08, 0.01);
  EXPECT_NEAR(e.offset_s, 0.08, std::max(3 * e.sigma_s, 0.005));
  EXPECT_THAT(late.time_offset_message, HasSubstr("ms, applied and the images tracked again"));
  const auto position_mm = [](const pipeline::CalibrateDatasetResult& r) {
    return 1e3 *
           pipeline::errors_vs_truth(r.extrinsics(), r.calibration.covariance, *r.truth).position;
  };
  EXPECT_LE(position_mm(late), 1.2 * position_mm(sync) + 0.1);
}

// docs/theory/noise-check.md: made by default, a positive scale over the tracks; the reported
// covariance is the checked one when the check rejected the model, shrunk from the model's
// towards the checked one but only to the check's bound when it found less noise, the model's
// otherwise. Turned off, the model's; its "less noise" level is recorded.
TEST_F(CalibrateDataset, NoiseCheckChoosesTheReportedCovarianceAndCanBeTurnedOff) {
  const fs::path out = scratch("noise-check");
  const auto r = calibrate_dataset(paper().string(), out.string(), cli_defaults_refined());
  auto json = read_json(out / "summary.json");
  const auto& nc = json["noise_check"];
  EXPECT_TRUE(nc["checked"].get<bool>());
  EXPECT_GT(nc["scale"].get<double>(), 0.0);
  EXPECT_GE(nc["tracks"].get<int>(), 2);
  const double reported = json["result"]["covariance"][0].get<double>();
  const double model = nc["refinement_model_covariance"][0].get<double>();
  const double checked = nc["batch_checked_covariance"][0].get<double>();
  const std::string verdict = nc["verdict"].get<std::string>();
  if (!nc["applied"].get<bool>()) {
    EXPECT_EQ(reported, model);
  } else if (verdict == "more noise") {
    EXPECT_EQ(reported, checked);
  } else {
    ASSERT_EQ(verdict, "less noise");
    EXPECT_LT(checked, reported);
    EXPECT_LT(reported, model);
    EXPECT_GT(nc["variance_ratio"].get<double>(), nc["scale"].get<double>());
    EXPECT_LT(nc["variance_ratio"].get<double>(), 1.0);
  }
  EXPECT_TRUE(r.calibration.noise_check.checked);
  EXPECT_THAT(r.BriefReport(), ContainsRegex("noise check over [0-9]+ tracks"));

  auto off = cli_defaults_refined();
  off.calibration.noise_check.enabled = false;
  const auto r_off = calibrate_dataset(paper().string(), out.string(), off);
  expect_complete_outputs_without_nan(out);
  json = read_json(out / "summary.json");
  EXPECT_FALSE(json["noise_check"]["checked"].get<bool>());
  EXPECT_EQ(json["noise_check"]["refinement_model_covariance"][0].get<double>(),
            json["result"]["covariance"][0].get<double>());
  EXPECT_FALSE(r_off.calibration.noise_check.checked);
  EXPECT_THAT(r_off.BriefReport(), HasSubstr("no noise check"));

  auto level = cli_defaults();
  level.calibration.noise_check.lower_level = 0.3;
  calibrate_dataset(paper().string(), out.string(), level);
  expect_complete_outputs_without_nan(out);
  json = read_json(out / "summary.json");
  EXPECT_EQ(json["noise_check"]["level_less_noise"].get<double>(), 0.3);
  EXPECT_EQ(json["noise_check"]["level_more_noise"].get<double>(), 0.01);
}

// A constant bearing error per track in the models: the summary, the terminal report and
// report.html name the two-part noise model; a negative sigma is refused.
TEST_F(CalibrateDataset, TrackBiasSigmaIsUsedAndNamedInEveryOutput) {
  const fs::path out = scratch("track-bias");
  auto o = cli_defaults_refined();
  o.calibration.noise.bearing_sigma = deg2rad(0.018);
  o.calibration.noise.track_bias_sigma = deg2rad(0.016);
  const auto r = calibrate_dataset(paper().string(), out.string(), o);
  expect_complete_outputs_without_nan(out);
  const auto json = read_json(out / "summary.json");
  EXPECT_NEAR(json["inputs"]["track_bias_sigma_deg"].get<double>(), 0.016, 1e-5);
  EXPECT_NEAR(json["inputs"]["bearing_sigma_deg"].get<double>(), 0.018, 1e-5);
  EXPECT_GT(json["noise_check"]["effective_track_bias_sigma_deg"].get<double>(), 0.0);
  EXPECT_THAT(r.BriefReport(), HasSubstr("bearing sigma 0.018 deg + 0.016 deg per track"));
  EXPECT_THAT(read_text(out / "report.html"), HasSubstr("0.016 deg per track"));

  o.calibration.noise.track_bias_sigma = deg2rad(-0.01);
  EXPECT_THAT(input_error_of([&] { calibrate_dataset(paper().string(), out.string(), o); }),
              HasSubstr("invalid calibration options: noise.track_bias_sigma must be >= 0"));
}

// Without turns the camera's position is not observable (Sec. 8.1): the camera yaw is
// determined, rho not; no extrinsics.yaml unless forced, and the verdict names the motion
// that would fix it.
TEST_F(CalibrateDataset, StraightRunIsNotDeterminedAndWritesNoExtrinsics) {
  const fs::path out = scratch("straight");
  const auto r = calibrate_dataset(straight().string(), out.string(), cli_defaults());
  EXPECT_FALSE(r.wrote_extrinsics);
  EXPECT_FALSE(r.calibration.observable());
  EXPECT_FALSE(fs::exists(out / "extrinsics.yaml"));
  EXPECT_THAT(r.calibration.observability.message, HasSubstr("not determined"));
  EXPECT_THAT(r.calibration.observability.message, HasSubstr("turn"));
  expect_complete_outputs_without_nan(out);
  const auto json = read_json(out / "summary.json");
  EXPECT_FALSE(json["observability"]["observable"].get<bool>());
  EXPECT_FALSE(json["observability"]["rho"]["determined"].get<bool>());
  EXPECT_TRUE(json["observability"]["yaw"]["determined"].get<bool>());
}

TEST_F(CalibrateDataset, StraightRunWithForceWritesExtrinsicsMarkedNotObservable) {
  const fs::path out = scratch("straight-force");
  auto o = cli_defaults();
  o.force = true;
  const auto r = calibrate_dataset(straight().string(), out.string(), o);
  EXPECT_TRUE(r.wrote_extrinsics);
  EXPECT_FALSE(r.calibration.observable());
  expect_complete_outputs_without_nan(out);
  const std::string yaml = read_text(out / "extrinsics.yaml");
  EXPECT_THAT(yaml, HasSubstr("\nobservable: false"));
  // Without turns rho is at best weakly determined (wheel noise bends the path a little):
  // its bound is infinite or above the 20 mm threshold of "determined".
  std::smatch m;
  ASSERT_TRUE(std::regex_search(yaml, m, std::regex("\ncrlb_rho: ([^\n]*)"))) << yaml;
  if (m[1] != ".inf") {
    EXPECT_GT(std::stod(m[1]), 0.02) << "crlb_rho: " << m[1];
  }
  const auto json = read_json(out / "summary.json");
  EXPECT_FALSE(json["observability"]["observable"].get<bool>());
  EXPECT_FALSE(json["observability"]["rho"]["determined"].get<bool>());
  EXPECT_TRUE(json["observability"]["yaw"]["determined"].get<bool>());
}

// What `--prior FILE`, `--phi` ... and the command line become: the prior of the options is the
// filter's, recorded in the summary; the caller's notes are warned about with the rest.
TEST_F(CalibrateDataset, PriorCommandAndNotesOfTheOptionsReachTheOutputs) {
  const fs::path out = scratch("prior");
  auto o = cli_defaults();
  o.calibration.prior.mean = {-0.3, 0.25, 0.3};
  o.calibration.prior.sigma = {0.2, 0.05, 0.2};
  o.command = "omnivert calibrate paper --out prior";
  o.notes = {"a note of the caller"};
  const auto r = calibrate_dataset(paper().string(), out.string(), o);
  expect_complete_outputs_without_nan(out);
  const auto json = read_json(out / "summary.json");
  const auto& prior = json["inputs"]["prior"];
  EXPECT_EQ(prior["phi"].get<double>(), -0.3);
  EXPECT_EQ(prior["rho"].get<double>(), 0.25);
  EXPECT_EQ(prior["psi"].get<double>(), 0.3);
  EXPECT_EQ(prior["sigma_rho"].get<double>(), 0.05);
  EXPECT_THAT(r.warnings, ::testing::Contains("a note of the caller"));
  EXPECT_THAT(json.dump(), HasSubstr("a note of the caller"));
  EXPECT_THAT(read_text(out / "report.html"), HasSubstr("omnivert calibrate paper --out prior"));
}

// Tracks of an earlier run give the same estimate without the images (tracks.csv holds the
// bearings to about 1e-9 rad); the output folder's own tracks.csv can be named (it is read
// before the folder is cleared).
TEST_F(CalibrateDataset, TracksFileGivesTheEstimateOfTracking) {
  const fs::path out = scratch("tracked"), again = scratch("from-tracks");
  const auto tracked = calibrate_dataset(paper().string(), out.string(), cli_defaults());
  const fs::path copy = scratch("tracks-copy") / "tracks.csv";
  fs::create_directories(copy.parent_path());
  fs::copy_file(out / "tracks.csv", copy);

  auto o = cli_defaults();
  o.tracks_file = copy.string();
  const auto from_file = calibrate_dataset(paper().string(), again.string(), o);
  expect_complete_outputs_without_nan(again);
  EXPECT_NEAR(from_file.extrinsics().phi, tracked.extrinsics().phi, 1e-6);
  EXPECT_NEAR(from_file.extrinsics().rho, tracked.extrinsics().rho, 1e-6);
  EXPECT_NEAR(from_file.extrinsics().psi, tracked.extrinsics().psi, 1e-6);
  EXPECT_EQ(read_text(again / "tracks.csv"), read_text(out / "tracks.csv"));
  EXPECT_EQ(from_file.frames, tracked.frames);
  EXPECT_EQ(from_file.detections, tracked.detections);

  o.tracks_file = (out / "tracks.csv").string();
  const auto in_place = calibrate_dataset(paper().string(), out.string(), o);
  EXPECT_TRUE(fs::exists(out / "tracks.csv"));
  expect_complete_outputs_without_nan(out);
  EXPECT_EQ(in_place.extrinsics().phi, from_file.extrinsics().phi);
  EXPECT_EQ(in_place.extrinsics().rho, from_file.extrinsics().rho);
  EXPECT_EQ(in_place.extrinsics().psi, from_file.extrinsics().psi);

  // Crowded lines' bearings weigh less: recorded, and another estimate.
  o.tracks_file = copy.string();
  o.input.crowded_sigma_scale = 4.0;
  const fs::path crowded_out = scratch("crowded");
  const auto crowded = calibrate_dataset(paper().string(), crowded_out.string(), o);
  const auto json = read_json(crowded_out / "summary.json");
  EXPECT_EQ(json["inputs"]["crowded_sigma_scale"].get<double>(), 4.0);
  EXPECT_GT(json["inputs"]["crowded_bearings"].get<int>(), 0);
  EXPECT_GT(crowded.input.crowded_bearings, 0);
  EXPECT_NE(crowded.extrinsics().phi, from_file.extrinsics().phi);
}

// Tracks of another dataset are refused by file and line, and leave no results.
TEST_F(CalibrateDataset, TracksOfAnotherDatasetAreRefusedByFileAndLine) {
  const fs::path out = scratch("paper-tracks");
  calibrate_dataset(paper().string(), out.string(), cli_defaults());
  auto o = cli_defaults();
  o.force = true;
  o.tracks_file = (out / "tracks.csv").string();
  const fs::path other_out = scratch("other-out");
  EXPECT_THAT(
      input_error_of([&] { calibrate_dataset(straight().string(), other_out.string(), o); }),
      ContainsRegex("tracks.csv:[0-9]+: frame 45 is not an image of .*straight "
                    "\\(it has 45\\)"));

  const fs::path other = scratch("tracks-other.csv");
  write_text(other, "frame,timestamp_ns,track_id,bearing_rad\n0,123,0,0.5\n");
  o.tracks_file = other.string();
  EXPECT_THAT(input_error_of([&] { calibrate_dataset(paper().string(), other_out.string(), o); }),
              ContainsRegex("tracks-other.csv:2: frame 0 has timestamp 123 but cam0/data.csv line "
                            "2 has [0-9]+: these tracks are not of this dataset"));
  EXPECT_FALSE(fs::exists(other_out / "summary.json"));
  EXPECT_FALSE(fs::exists(other_out / "extrinsics.yaml"));
}

// Bearings of lines at least 70% of the annulus used: 9 tracks in the corridor -> a warning
// that suggests shorter lines, in the result and in summary.json; the default: no such warning.
TEST_F(CalibrateDataset, FewTracksAreWarnedAboutWithAdvice) {
  const fs::path out = scratch("few-tracks");
  auto o = cli_defaults();
  o.force = true;
  o.input.min_annulus_fraction = 0.7;
  o.input.enough_tracks = 0;  // as --calibration-length-fraction 0.7 does
  const auto r = calibrate_dataset(paper().string(), out.string(), o);
  expect_complete_outputs_without_nan(out);
  EXPECT_THAT(joined(r.warnings), ContainsRegex("only [0-9]+ lines were tracked"));
  EXPECT_THAT(joined(r.warnings), HasSubstr("--calibration-length-fraction 0.25"));
  EXPECT_THAT(read_text(out / "summary.json"), ContainsRegex("only [0-9]+ lines were tracked"));
  EXPECT_LT(r.input.tracks, 15);
  EXPECT_GT(r.input.short_bearings, 0);

  o.input = cli_defaults().input;
  const auto d = calibrate_dataset(paper().string(), scratch("few-tracks-default").string(), o);
  EXPECT_THAT(joined(d.warnings), Not(HasSubstr("lines were tracked")));
}

}  // namespace
}  // namespace omnivert::testing
