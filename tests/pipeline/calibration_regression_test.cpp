// Rendered runs on which the calibration once went wrong, each calibrated from pixels as
// `omnivert calibrate DATASET --out DIR --force` does (no refinement) and checked against its
// ground truth in summary.json.
//
// The filter's batch window solved from several starts (CalibrationOptions::
// filter.bootstrap_starts, docs/theory/window.md#starts):
// - WindowStarts: the office, zigzag, seed 11 run, whose window solved from the prior alone
//   ends in a local minimum (camera yaw 2.0 degrees off, NEES 9175);
// - WindowFlowYaw: the corridor, zigzag, seed 57 run with the camera mounted at -107.5 degrees
//   of yaw (phi -0.915, psi -0.961 rad: scripts/eval-calibration's VARY_EXTRINSICS draw for
//   seed 57), where every start at the prior's camera yaw ends far off (the filter 33 degrees
//   off in phi, NEES 1e10) without the starts at the bearings' flow yaw
//   (calib::camera_yaw_from_flow).
// Each must end near the truth.
//
// The filter's crossing guard (CalibrationOptions::association.crossing_guard), office, paper
// trajectory, each with the camera mount scripts/eval-calibration's VARY_EXTRINSICS draws for
// its seed (docs/theory/association.md#lines-that-cross):
// - CrossingGuard, seed 32: a line's track starts at frame 80 0.5 degree from a line tracked
//   over the whole run, and the two part to 1.1 degree. Judged by the predictions alone, the
//   new feature (depth unknown) is guarded from its start, never updated, and keeps guarding
//   the long line to the end: 57 bearings left out instead of 39, the bound of the filter's
//   problem for psi 0.37 degree instead of 0.22, its psi error -0.82 degree (-0.36 when the
//   guard judges a feature seen in the frame by its bearing; the refinement's -0.40).
// - CrossingGuardWindow, seed 36: a line's last two bearings in the start-up window are pushed
//   0.09-0.12 degree by a line whose track starts two frames after the window; with them, the
//   filter ends 2.6 mm off in rho, NEES 19.4; left out (guard_before_starts, in the window for
//   tracks that start after it), 2.1 mm, NEES 10.4 (the refinement's: 1.2 mm, 12.2).

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "calibration_fixture.hpp"

namespace omnivert::testing {
namespace {

// The filter's figures of one run (summary.json).
struct FilterFigures {
  double yaw_deg = 0, position_mm = 0, psi_deg = 0, rho_mm = 0, nees = 0;
  double psi_crlb = 0;  // [rad]
  int guarded = 0;
};

class CalibrationRegression : public SimulatedDatasets {
 protected:
  // Simulates `run` as `name`, calibrates it with the CLI's defaults and --force, and reads
  // the filter's figures.
  static FilterFigures calibrate(const std::string& name, const SimulatedRun& run) {
    const fs::path out = scratch(name);
    pipeline::CalibrateDatasetOptions o = cli_defaults();
    o.force = true;
    pipeline::calibrate_dataset(dataset(name, run).string(), out.string(), o);
    const nlohmann::json js = read_json(out / "summary.json");
    const nlohmann::json& e = js["errors_vs_ground_truth"]["filter"];
    FilterFigures f;
    f.yaw_deg = e["yaw_deg"].get<double>();
    f.position_mm = e["position_mm"].get<double>();
    f.psi_deg = e["psi_deg"].get<double>();
    f.rho_mm = e["rho_mm"].get<double>();
    f.nees = e["nees"].get<double>();
    f.psi_crlb = js["observability"]["psi"]["crlb"].get<double>();
    f.guarded = js["filter"]["bearings_guarded"].get<int>();
    std::printf(
        "%s, filter: camera yaw error %.4f deg, position error %.3f mm, psi error %.4f deg, rho "
        "error %.3f mm, NEES %.2f, psi bound %.5f rad, %d bearings guarded\n",
        name.c_str(),
        f.yaw_deg,
        f.position_mm,
        f.psi_deg,
        f.rho_mm,
        f.nees,
        f.psi_crlb,
        f.guarded);
    return f;
  }
};

TEST_F(CalibrationRegression, WindowStarts) {
  const FilterFigures f = calibrate("window-starts", {"office", "zigzag", 11, 0});
  EXPECT_LE(std::abs(f.yaw_deg), 0.5);
  EXPECT_LE(f.position_mm, 5.0);
}

TEST_F(CalibrationRegression, WindowFlowYaw) {
  const FilterFigures f =
      calibrate("window-flow-yaw",
                {"corridor",
                 "zigzag",
                 57,
                 0,
                 sim::Extrinsics{-0.9148685728348462, 0.21793729008033075, -0.961378377305627}});
  EXPECT_LE(std::abs(f.yaw_deg), 0.5);
  EXPECT_LE(f.position_mm, 5.0);
}

TEST_F(CalibrationRegression, CrossingGuard) {
  const FilterFigures f =
      calibrate("crossing-guard",
                {"office",
                 "paper",
                 32,
                 0,
                 sim::Extrinsics{-0.8451564322933918, 0.14272335789299767, -0.39374332579442917}});
  EXPECT_LE(std::abs(f.psi_deg), 0.55) << "measured -0.36; -0.82 with the guard on predictions";
  EXPECT_LE(f.psi_crlb, 0.0047)  // 0.27 degree
      << "the filter's problem lost bearings (measured 0.0039; 0.0064 with the guard on "
         "predictions)";
  EXPECT_LE(f.guarded, 48) << "measured 39; 57 with the guard on predictions";
}

TEST_F(CalibrationRegression, CrossingGuardWindow) {
  const FilterFigures f =
      calibrate("crossing-guard-window",
                {"office",
                 "paper",
                 36,
                 0,
                 sim::Extrinsics{-0.3425989589338041, 0.2966427833152556, 0.918495070954692}});
  EXPECT_LE(f.nees, 14.0) << "measured 10.4; 19.4 with the window's tail kept";
  EXPECT_GE(f.rho_mm, -2.4) << "measured -2.08; -2.64 with the window's tail kept";
}

}  // namespace
}  // namespace omnivert::testing
