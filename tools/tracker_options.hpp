#pragma once
// Command-line options of the tracker (Sec. 4, 9.1), shared by track and calibrate.

#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"

#include "omnivert/core/angles.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert::cli {

struct TrackerFlags {
  std::string rules = "recommended";
  bool no_mutual = false;
  bool no_gate = false;
  int look_back = 20;
  // Each flag not given keeps the value of the rule set (--rules) or of TrackerOptions.
  std::optional<double> f1, f2, f3, partial_area_scale, partial_side_scale;
  std::string gate_candidates = "default";  // on|off|default (the rule set's)
  std::optional<double> gate_min_distance, gate_tolerance_deg;
  std::string same_polarity = "default";  // on|off|default (the rule set's)
  std::optional<double> continuity_deg;
  std::string continuity_model = "default";  // link|track|default
  std::optional<double> continuity_path_curvature, continuity_turn_curvature;
  std::optional<double> look_back_f1;
  std::string heads_only = "default";  // on|off|default
  std::optional<double> confirm_f1, confirm_deg;
  std::string triangulate = "default";  // on|off|default
  std::optional<double> predict_f1, camera_yaw_deg;

  // The options these flags select (the wheel base is filled in from the dataset).
  TrackerOptions options() const {
    TrackerOptions o =
        rules == "paper" ? paper_tracker_options() : recommended_dataset_tracker_options();
    if (no_mutual) o.mutual = false;
    if (no_gate) o.gate.enabled = false;
    o.look_back = look_back;
    if (f1) o.match.f1 = *f1;
    if (f2) o.match.f2 = *f2;
    if (f3) o.match.f3 = *f3;
    if (partial_area_scale) o.match.partial_area_scale = *partial_area_scale;
    if (partial_side_scale) o.match.partial_side_scale = *partial_side_scale;
    if (gate_candidates != "default") o.gate_candidates = gate_candidates == "on";
    if (continuity_deg) o.continuity_tolerance = deg2rad(*continuity_deg);
    if (continuity_model != "default") {
      o.continuity_model = continuity_model == "track" ? TrackerOptions::ContinuityModel::kTrack
                                                       : TrackerOptions::ContinuityModel::kLink;
    }
    if (continuity_path_curvature) o.continuity_path_curvature = *continuity_path_curvature;
    if (continuity_turn_curvature) o.continuity_turn_curvature = *continuity_turn_curvature;
    if (look_back_f1) o.look_back_f1 = *look_back_f1;
    if (heads_only != "default") o.heads_only = heads_only == "on";
    if (confirm_f1) o.confirm_f1 = *confirm_f1;
    if (confirm_deg) o.confirm_tolerance = deg2rad(*confirm_deg);
    if (same_polarity != "default") o.same_polarity = same_polarity == "on";
    if (triangulate != "default") o.triangulate = triangulate == "on";
    if (predict_f1) o.predict_f1 = *predict_f1;
    if (camera_yaw_deg) o.camera_yaw = deg2rad(*camera_yaw_deg);
    if (gate_min_distance) o.gate.min_feature_distance = *gate_min_distance;
    if (gate_tolerance_deg) o.gate.bearing_tolerance = deg2rad(*gate_tolerance_deg);
    return o;
  }
};

// The help group of these options.
inline constexpr const char* kTrackingGroup = "Tracking (Sec. 4, 9.1)";

// The triangulated prediction's options (TrackerOptions::triangulate, predict_f1, camera_yaw).
inline void add_prediction_options(CLI::App* cmd, TrackerFlags& t, const std::string& g) {
  cmd->add_option("--triangulate",
                  t.triangulate,
                  "on: predict a track's bearing from its line's position, triangulated from its "
                  "bearings and the wheels during straight travel (needs track continuity, track "
                  "model; default: the rule set's)")
      ->check(CLI::IsMember({"on", "off", "default"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--predict-f1",
                  t.predict_f1,
                  "Links by prediction: a line left unmatched joins the track whose triangulated "
                  "prediction it alone meets within --confirm-tolerance, up to this descriptor "
                  "distance (needs --triangulate on; 0: off; default: the rule set's)")
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--camera-yaw",
                  t.camera_yaw_deg,
                  "The camera's yaw on the robot, phi + psi [degrees], for the triangulated "
                  "prediction (default: estimated from the tracks' parallax)")
      ->check(CLI::Range(-360.0, 360.0))
      ->group(g);
}

// Tests 1-3 (eq. 8-10) and the occluder-tolerant distances.
inline void add_descriptor_test_options(CLI::App* cmd, TrackerFlags& t, const std::string& g) {
  cmd->add_option("--f1",
                  t.f1,
                  "Test 1, eq. (8): min distance <= F1 (default: the rule set's: paper 1.05, "
                  "recommended 0.6)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--f2", t.f2, "Test 2, eq. (9): min <= F2 * mean (default 0.75)")
      ->check(CLI::Range(0.0, 1.0))
      ->group(g);
  cmd->add_option("--f3", t.f3, "Test 3, eq. (10): min <= F3 * second min (default 0.8)")
      ->check(CLI::Range(0.0, 1.0))
      ->group(g);
  cmd->add_option("--partial-area-scale",
                  t.partial_area_scale,
                  "Occluder-tolerant descriptor distance: where one of the three areas holds more "
                  "than (s-1)/s of the squared distance, the other two decide, scaled by s "
                  "(e.g. 2 in scenes with people; default 0: off, eq. 6)")
      ->check(CLI::Number)
      ->group(g);
  cmd->add_option("--partial-side-scale",
                  t.partial_side_scale,
                  "Occluder-tolerant descriptor distance by the line's sides: the distance may "
                  "also be s times the closer side's (a person beside the line changes one "
                  "side; e.g. 2 with people; default 0: off)")
      ->check(CLI::Number)
      ->group(g);
}

inline void add_tracker_options(CLI::App* cmd, TrackerFlags& t) {
  const std::string g = kTrackingGroup;
  cmd->add_option(
         "--rules",
         t.rules,
         "paper: the three matching rules alone; recommended: plus mutual (one-to-one), same "
         "edge polarity, the odometry bearing gate, track continuity, F1 0.6 (0.5 across a "
         "look-back gap) and confirmed F1 (docs/tracking.md)")
      ->check(CLI::IsMember({"paper", "recommended"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_flag("--no-mutual", t.no_mutual, "Without the mutual (one-to-one) constraint")->group(g);
  cmd->add_flag("--no-gate", t.no_gate, "Without the odometry bearing gate")->group(g);
  cmd->add_option("--look-back", t.look_back, "Frames searched back for an unmatched line")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str()
      ->group(g);
  cmd->add_option(
         "--gate-candidates",
         t.gate_candidates,
         "on: tests 1 and 3 and the mutual check among the lines the odometry gate admits; "
         "off: the gate only vetoes the nearest line (default: the rule set's)")
      ->check(CLI::IsMember({"on", "off", "default"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--same-polarity",
                  t.same_polarity,
                  "on: a line is matched only to lines of the same edge polarity (default: the "
                  "rule set's)")
      ->check(CLI::IsMember({"on", "off", "default"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--continuity",
                  t.continuity_deg,
                  "Track continuity tolerance [degrees]: refuse links that deviate more from the "
                  "track's predicted bearing (needs wheel data; 0: off; default: the rule set's: "
                  "recommended 0.8)")
      ->check(CLI::Range(0.0, 179.0))
      ->group(g);
  cmd->add_option("--continuity-model",
                  t.continuity_model,
                  "Track continuity prediction: link (parallax per metre of the observation "
                  "linked to, from its own link) or track (per metre and per radian turned, "
                  "inherited along the track; checks look-back links and turns too) (default: "
                  "the rule set's)")
      ->check(CLI::IsMember({"link", "track", "default"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--continuity-path-curvature",
                  t.continuity_path_curvature,
                  "Track continuity (track model): unpredicted bearing change per metre^2 "
                  "driven [rad/m^2] (default 0.5)")
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--continuity-turn-curvature",
                  t.continuity_turn_curvature,
                  "Track continuity (track model): unpredicted bearing change per radian^2 "
                  "turned [rad/rad^2] (default 0.3)")
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--look-back-f1",
                  t.look_back_f1,
                  "Test 1 for links across a look-back gap (2+ frames back): min distance <= "
                  "this (0: F1; default: the rule set's: paper 0, recommended 0.5)")
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--confirm-f1",
                  t.confirm_f1,
                  "Confirmed F1: accept a descriptor distance above F1 (or the look-back F1) up "
                  "to this when the track's motion predicts the line to --confirm-tolerance and "
                  "no other line is near the prediction (needs track continuity; 0: off; "
                  "default: the rule set's: paper 0, recommended 1.05)")
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--confirm-tolerance",
                  t.confirm_deg,
                  "Confirmed F1: largest deviation from the track's predicted bearing [degrees] "
                  "(default: the rule set's: recommended 0.3)")
      ->check(CLI::Range(0.0, 179.0))
      ->group(g);
  add_prediction_options(cmd, t, g);
  cmd->add_option("--heads-only",
                  t.heads_only,
                  "on: a look-back link only to a track's latest observation (no forks) "
                  "(default: the rule set's)")
      ->check(CLI::IsMember({"on", "off", "default"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--gate-min-distance",
                  t.gate_min_distance,
                  "Odometry gate: nearest distance of a line from the camera [m] (default 0.5)")
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--gate-tolerance",
                  t.gate_tolerance_deg,
                  "Odometry gate: bearing detection tolerance [degrees] (default 2)")
      ->check(CLI::Range(0.0, 179.0))
      ->group(g);
  add_descriptor_test_options(cmd, t, g);
}

}  // namespace omnivert::cli
