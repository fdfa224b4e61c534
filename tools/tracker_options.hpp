#pragma once
// Command-line options of the tracker (Sec. 4, 9.1), shared by track and calibrate.

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "omnivert/match/tracker.hpp"

namespace omnivert::cli {

struct TrackerFlags {
  std::string rules = "recommended";
  bool no_mutual = false;
  bool no_gate = false;
  int look_back = 20;
  double f1 = 1.05, f2 = 0.75, f3 = 0.8;

  // The options these flags select (the wheel base is filled in from the dataset).
  TrackerOptions options() const {
    TrackerOptions o = rules == "paper" ? paper_tracker_options() : recommended_tracker_options(1.0);
    if (no_mutual) o.mutual = false;
    if (no_gate) o.gate.enabled = false;
    o.look_back = look_back;
    o.match.f1 = f1;
    o.match.f2 = f2;
    o.match.f3 = f3;
    return o;
  }
};

inline void add_tracker_options(CLI::App* cmd, TrackerFlags& t) {
  const std::string g = "Tracking (Sec. 4, 9.1)";
  cmd->add_option("--rules", t.rules,
                  "paper: the three matching rules alone; recommended: plus mutual (one-to-one) "
                  "matching and the odometry bearing gate (docs/tracking.md)")
      ->check(CLI::IsMember({"paper", "recommended"}))
      ->capture_default_str()
      ->group(g);
  cmd->add_flag("--no-mutual", t.no_mutual, "Without the mutual (one-to-one) constraint")->group(g);
  cmd->add_flag("--no-gate", t.no_gate, "Without the odometry bearing gate")->group(g);
  cmd->add_option("--look-back", t.look_back, "Frames searched back for an unmatched line")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str()
      ->group(g);
  cmd->add_option("--f1", t.f1, "Test 1, eq. (8): min distance <= F1")->check(CLI::PositiveNumber)->capture_default_str()->group(g);
  cmd->add_option("--f2", t.f2, "Test 2, eq. (9): min <= F2 * mean")->check(CLI::Range(0.0, 1.0))->capture_default_str()->group(g);
  cmd->add_option("--f3", t.f3, "Test 3, eq. (10): min <= F3 * second min")->check(CLI::Range(0.0, 1.0))->capture_default_str()->group(g);
}

}  // namespace omnivert::cli
