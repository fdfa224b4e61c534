// Monte-Carlo study of the self-calibration: many synthetic runs of the paper's
// trajectory from the paper's rough prior; errors against truth, RMS against the
// Cramer-Rao bound, NEES against the chi-square interval. Filter alone and with the batch
// refinement; with --refine also both with the covariances after the noise check
// (calib::calibrate, docs/theory/noise-check.md).
//
//   calib_monte_carlo [--runs 50] [--sigma-deg 0.3] [--init anchored|inverse|naive]
//                     [--inflation 1] [--iterations 3] [--trajectory paper|zigzag]
//                     [--bootstrap RAD] [--refine] [--seed 1] [--correlation A]
//                     [--lateral M] [--break P] [--no-merge] [--model-sigma-deg S]
//                     [--bias-deg B] [--model-bias-deg B] [--lower-level L]
//                     [--legs N] [--length M] [--features N] [--visible M] [--max-distance M]
// --init anchored (default): anchored inverse depth + camera-pose extrinsics, with the batch
//   window up to the first turn (--bootstrap, rad of rotation; 0: no window);
// --init inverse: the paper's state eq. (28) with undelayed inverse-distance features;
// --init naive: the naive initialisation of docs/theory/filter.md.
// --correlation A: AR(1) coefficient of each track's bearing errors from frame to frame.
// --lateral M: sideways slip per step allowed by the batch problems (window, refinement).
// --break P: each track gets a new id with probability P per frame (a tracker that loses
//   lines and finds them again; docs/theory/association.md#pieces-of-one-line).
// --model-sigma-deg S: the bearing sigma the filter and the batches assume (default: the
//   simulated one), to study the noise check (docs/theory/noise-check.md).
// --bias-deg B: a constant bearing error per line, sigma B degrees (SyntheticRunOptions::
//   track_bias_sigma); --model-bias-deg B: the one the estimators assume (CalibrationOptions::
//   track_bias_sigma; default: the simulated one).
// --lower-level L: the noise check's "less noise" level (CalibrationOptions::noise_check.
//   lower_level; default: the tool's).
// --legs, --length, --features, --visible, --max-distance: a long run whose features enter and
//   leave the view (SyntheticRunOptions zigzag_legs, straight_length, num_features,
//   visible_range, max_distance), e.g. a 90 m zigzag of 40 legs among 400 lines seen within 6 m.
// --no-merge: the pieces of one line are not joined, in the filter nor in the refinement
//   (CalibrationOptions::association.join_pieces).
// Diagnostics (environment): PRIOR_AT_TRUTH=s (prior centred on truth, sigma s), PRIOR_SIGMA=s,
// DMIN/DMAX (feature distance prior), CONVERT (convert_ratio), NO_SECOND_ORDER,
// NO_FILTER_JOIN (CalibrationOptions::association.join_pieces off), VERBOSE, WINDOW_NEES.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "calib/updater.hpp"
#include "core/progress.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/calib/observability.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/calib/track_ids.hpp"
#include "omnivert/core/angles.hpp"

using namespace omnivert;
using namespace omnivert::calib;

namespace {

struct Stats {
  std::vector<double> pos_mm, yaw_deg, nees;
  std::vector<double> yaw_err, yaw_z2;  // camera yaw phi + psi: error [rad], its e^2 / sigma^2
  std::vector<Eigen::Vector3d> err;
  int failures = 0;
  void add(const Extrinsics& est, const Eigen::Matrix3d& cov, const Extrinsics& truth) {
    Eigen::Vector3d e(
        angle_diff(est.phi, truth.phi), est.rho - truth.rho, angle_diff(est.psi, truth.psi));
    if (!e.allFinite() || !cov.allFinite()) {
      ++failures;
      return;
    }
    err.push_back(e);
    pos_mm.push_back(1e3 * (est.position() - truth.position()).norm());
    yaw_deg.push_back(std::abs(rad2deg(angle_diff(est.yaw(), truth.yaw()))));
    nees.push_back(e.dot(cov.ldlt().solve(e)));
    const double ey = angle_diff(est.yaw(), truth.yaw());
    yaw_err.push_back(ey);
    yaw_z2.push_back(ey * ey / (cov(0, 0) + cov(2, 2) + 2.0 * cov(0, 2)));
  }
  Eigen::Vector3d rms() const {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    for (const auto& e : err) r += e.cwiseProduct(e);
    return (r / std::max<double>(static_cast<double>(err.size()), 1.0)).cwiseSqrt();
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void print(const char* name, const Stats& s, const Eigen::Vector3d& crlb, double crlb_yaw) {
  const int n = static_cast<int>(s.err.size());
  const Eigen::Vector3d rms = s.rms();
  double mean_nees = 0;
  for (double v : s.nees) mean_nees += v;
  mean_nees /= std::max(n, 1);
  const double lo = chi2_quantile(0.025, 3 * n) / n, hi = chi2_quantile(0.975, 3 * n) / n;
  std::printf("%-22s runs %3d (failed %d)\n", name, n, s.failures);
  std::printf("  median |position error| %.2f mm   median |yaw error| %.3f deg\n",
              median(s.pos_mm),
              median(s.yaw_deg));
  std::printf(
      "  RMS phi %.3f deg (%.2f x CRLB)  rho %.2f mm (%.2f x CRLB)  psi %.3f deg (%.2f x CRLB)\n",
      rad2deg(rms(0)),
      rms(0) / crlb(0),
      1e3 * rms(1),
      rms(1) / crlb(1),
      rad2deg(rms(2)),
      rms(2) / crlb(2));
  double yaw_ms = 0.0, yaw_z2 = 0.0;
  for (std::size_t i = 0; i < s.yaw_err.size(); ++i) {
    yaw_ms += s.yaw_err[i] * s.yaw_err[i];
    yaw_z2 += s.yaw_z2[i];
  }
  yaw_ms /= std::max(n, 1);
  yaw_z2 /= std::max(n, 1);
  std::printf("  camera yaw: RMS %.4f deg (%.2f x CRLB), mean e^2 / sigma^2 %.2f\n",
              rad2deg(std::sqrt(yaw_ms)),
              std::sqrt(yaw_ms) / crlb_yaw,
              yaw_z2);
  std::printf("  mean NEES %.2f   95%% interval [%.2f, %.2f]  -> %s\n",
              mean_nees,
              lo,
              hi,
              (mean_nees >= lo && mean_nees <= hi) ? "consistent" : "INCONSISTENT");
}

struct Args {
  int runs = 50, iterations = FilterOptions{}.update_iterations;
  bool refine = false;
  double bootstrap = FilterOptions{}.bootstrap_rotation;
  bool merge = true;
  double sigma_deg = 0.3, model_sigma_deg = -1.0, inflation = 1.0, correlation = 0.0,
         break_probability = 0.0;
  double lateral = RobotModel{}.lateral_sigma;
  double bias_deg = 0.0, model_bias_deg = -1.0;
  double lower_level = NoiseCheckOptions{}.lower_level;
  std::string init = "anchored", trajectory = "paper";
  std::uint64_t seed = 1;
  // A long run (SyntheticRunOptions): 0 keeps the trajectory's default.
  int legs = 0, features = 0;
  double length = 0.0, visible = 0.0, max_distance = 0.0;
};

// The command line; exits with 2 on a bad argument.
Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", argv[i]);
        std::exit(2);
      }
      return argv[++i];
    };
    if (!std::strcmp(argv[i], "--runs"))
      a.runs = std::atoi(next());
    else if (!std::strcmp(argv[i], "--sigma-deg"))
      a.sigma_deg = std::atof(next());
    else if (!std::strcmp(argv[i],
                          "--model-sigma-deg"))  // what the filter assumes (default: the truth)
      a.model_sigma_deg = std::atof(next());
    else if (!std::strcmp(argv[i], "--bias-deg"))
      a.bias_deg = std::atof(next());
    else if (!std::strcmp(argv[i], "--model-bias-deg"))
      a.model_bias_deg = std::atof(next());
    else if (!std::strcmp(argv[i], "--lower-level"))
      a.lower_level = std::atof(next());
    else if (!std::strcmp(argv[i], "--correlation"))
      a.correlation = std::atof(next());
    else if (!std::strcmp(argv[i], "--break"))
      a.break_probability = std::atof(next());
    else if (!std::strcmp(argv[i], "--init"))
      a.init = next();
    else if (!std::strcmp(argv[i], "--inflation"))
      a.inflation = std::atof(next());
    else if (!std::strcmp(argv[i], "--iterations"))
      a.iterations = std::atoi(next());
    else if (!std::strcmp(argv[i], "--trajectory"))
      a.trajectory = next();
    else if (!std::strcmp(argv[i], "--refine"))
      a.refine = true;
    else if (!std::strcmp(argv[i], "--bootstrap"))
      a.bootstrap = std::atof(next());
    else if (!std::strcmp(argv[i], "--lateral"))
      a.lateral = std::atof(next());
    else if (!std::strcmp(argv[i], "--no-merge"))
      a.merge = false;
    else if (!std::strcmp(argv[i], "--seed"))
      a.seed = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--legs"))
      a.legs = std::atoi(next());
    else if (!std::strcmp(argv[i], "--features"))
      a.features = std::atoi(next());
    else if (!std::strcmp(argv[i], "--length"))
      a.length = std::atof(next());
    else if (!std::strcmp(argv[i], "--visible"))
      a.visible = std::atof(next());
    else if (!std::strcmp(argv[i], "--max-distance"))
      a.max_distance = std::atof(next());
    else {
      std::fprintf(stderr, "unknown argument %s\n", argv[i]);
      std::exit(2);
    }
  }
  return a;
}

// The simulated runs.
SyntheticRunOptions synthetic_options(const Args& a) {
  SyntheticRunOptions so;
  so.bearing_sigma = deg2rad(a.sigma_deg);
  so.bearing_correlation = a.correlation;
  so.track_bias_sigma = deg2rad(a.bias_deg);
  so.break_probability = a.break_probability;
  so.trajectory = a.trajectory == "zigzag" ? Trajectory::kZigzag : Trajectory::kPaper;
  if (a.legs > 0) so.zigzag_legs = a.legs;
  if (a.features > 0) so.num_features = a.features;
  if (a.length > 0) so.straight_length = a.length;
  if (a.visible > 0) so.visible_range = a.visible;
  if (a.max_distance > 0) so.max_distance = a.max_distance;
  return so;
}

// The estimators' options, with the diagnostics from the environment.
CalibrationOptions filter_options(const Args& a, const SyntheticRunOptions& so) {
  CalibrationOptions fo;
  fo.robot.wheel_base = so.wheel_base;
  fo.robot.odometry_K = so.odometry_K;
  fo.filter.odometry_inflation = a.inflation;
  fo.noise.bearing_sigma = a.model_sigma_deg > 0 ? deg2rad(a.model_sigma_deg) : so.bearing_sigma;
  fo.noise.track_bias_sigma =
      a.model_bias_deg >= 0 ? deg2rad(a.model_bias_deg) : so.track_bias_sigma;
  fo.filter.update_iterations = a.iterations;
  fo.robot.lateral_sigma = a.lateral;
  fo.filter.feature_init = a.init == "naive"     ? FeatureInit::kNaive
                           : a.init == "inverse" ? FeatureInit::kInverseDistance
                                                 : FeatureInit::kAnchoredInverseDepth;

  if (const char* c = std::getenv("PRIOR_AT_TRUTH")) {  // diagnostics: prior centred on truth
    fo.prior.mean = so.truth;
    fo.prior.sigma = Eigen::Vector3d(std::atof(c), std::atof(c) / 8, std::atof(c));
  }
  if (const char* c = std::getenv("PRIOR_SIGMA"))  // diagnostics
    fo.prior.sigma = Eigen::Vector3d(std::atof(c), std::atof(c) / 8, std::atof(c));
  if (const char* c = std::getenv("DMIN")) fo.filter.min_feature_distance = std::atof(c);
  if (const char* c = std::getenv("DMAX")) fo.filter.max_feature_distance = std::atof(c);
  if (const char* c = std::getenv("CONVERT")) fo.filter.convert_ratio = std::atof(c);
  if (std::getenv("NO_SECOND_ORDER")) fo.filter.second_order_noise = false;
  if (std::getenv("NO_FILTER_JOIN")) fo.association.join_pieces = false;
  fo.filter.bootstrap_rotation = a.bootstrap;
  return fo;
}

// What the runs add up.
struct Totals {
  Stats filt, ref, ref_checked, filt_checked;
  std::vector<double> scales;
  int applied = 0, filter_applied = 0;
  Eigen::Vector3d crlb_sq = Eigen::Vector3d::Zero();
  Eigen::Vector3d crlb_joined_sq = Eigen::Vector3d::Zero();
  double crlb_yaw_sq = 0, crlb_pos_sq = 0;
  int all_merges = 0, wrong_merges = 0, filter_joins = 0, filter_wrong = 0;
};

// Diagnostics (MISSING): tracks of at least 3 bearings that the filter does not hold.
void print_missing_tracks(const SyntheticRun& run, const FilterResult& fr) {
  std::map<int, std::pair<int, int>> span;
  std::map<int, int> n;
  for (int k = 0; k < static_cast<int>(run.run.frames.size()); ++k)
    for (const auto& o : run.run.frames[k].observations) {
      if (!n[o.track_id]++) span[o.track_id].first = k;
      span[o.track_id].second = k;
    }
  for (const auto& [id, c] : n)
    if (c >= 3 && !fr.tracks.count(id))
      std::printf("missing track %d: %d bearings, frames %d-%d (window %d)\n",
                  id,
                  c,
                  span[id].first,
                  span[id].second,
                  fr.window_frames);
}

// Diagnostics (WINDOW_NEES): the NEES at the end of the batch window.
void print_window_nees(const SyntheticRun& run, const FilterResult& fr, const Stats& filt) {
  const FrameEstimate& w = fr.history[static_cast<std::size_t>(fr.window_frames - 1)];
  const Eigen::Vector3d e(angle_diff(w.extrinsics.phi, run.truth.phi),
                          w.extrinsics.rho - run.truth.rho,
                          angle_diff(w.extrinsics.psi, run.truth.psi));
  std::printf("window %d frames of %zu: nees %.2f; end %.2f; joins %zu\n",
              fr.window_frames,
              run.run.frames.size(),
              e.dot(w.covariance.ldlt().solve(e)),
              filt.nees.back(),
              fr.joins.size());
}

// The Cramer-Rao bound of this run (Fisher information at the truth), and with --break the
// bound with each line's pieces under one id (what joining them can reach).
void add_crlb(const SyntheticRun& run, const CalibrationOptions& fo, const Args& a, Totals& t) {
  BatchPoint truth;
  truth.poses = run.true_poses;
  truth.extrinsics = run.truth;
  for (const auto& [id, j] : run.track_feature) truth.features[id] = run.features[j];
  const ObservabilityReport obs = analyse_observability(run.run, fo, truth);
  t.crlb_sq += Eigen::Vector3d(obs.phi.crlb, obs.rho.crlb, obs.psi.crlb).cwiseAbs2();
  t.crlb_yaw_sq += obs.yaw.crlb * obs.yaw.crlb;
  t.crlb_pos_sq += obs.x.crlb * obs.x.crlb + obs.y.crlb * obs.y.crlb;
  if (a.break_probability > 0.0) {
    CalibrationRun joined = run.run;
    BatchPoint at = truth;
    at.features.clear();
    for (FrameInput& f : joined.frames)
      for (BearingObservation& o : f.observations) {
        o.track_id = run.track_feature.at(o.track_id);
        at.features[o.track_id] = run.features[static_cast<std::size_t>(o.track_id)];
      }
    const ObservabilityReport j = analyse_observability(joined, fo, at);
    t.crlb_joined_sq += Eigen::Vector3d(j.phi.crlb, j.rho.crlb, j.psi.crlb).cwiseAbs2();
  }
}

// With --refine: the refinement's errors, the noise check, and the joins of pieces.
void add_refinement(int r, const SyntheticRun& run, const CalibrationResult& cr, Totals& t) {
  if (cr.refinement.covariance_ok) {
    t.ref.add(cr.refinement.extrinsics, cr.noise_check.refinement_model_covariance, run.truth);
    if (cr.noise_check.checked) {
      t.scales.push_back(cr.noise_check.check.scale);
      t.applied += cr.noise_check.applied ? 1 : 0;
      t.filter_applied += cr.noise_check.filter_applied ? 1 : 0;
      t.ref_checked.add(cr.refinement.extrinsics, cr.refinement.covariance, run.truth);
      t.filt_checked.add(cr.filter.extrinsics, cr.filter.covariance, run.truth);
    }
  } else {
    ++t.ref.failures;
  }
  // Joins of two different lines (pieces whose true features differ).
  auto of_two_lines = [&run](const std::vector<omnivert::calib::TrackJoin>& joins) {
    int n = 0;
    for (const auto& [a, c] : joins) {
      const auto ia = run.track_feature.find(a), ic = run.track_feature.find(c);
      n += ia != run.track_feature.end() && ic != run.track_feature.end() &&
           ia->second != ic->second;
    }
    return n;
  };
  const int wrong = of_two_lines(cr.refinement.merges);
  t.wrong_merges += wrong;
  t.all_merges += static_cast<int>(cr.refinement.merges.size());
  t.filter_joins += static_cast<int>(cr.filter.joins.size());
  t.filter_wrong += of_two_lines(cr.filter.joins);
  if (std::getenv("VERBOSE"))
    std::printf(
        "run %d: refinement %s nees %.1f  phi %.4f rho %.4f psi %.4f  merges %zu "
        "(%d of two lines) splits %d\n",
        r,
        cr.refinement.covariance_ok ? "" : "(no covariance)",
        cr.refinement.covariance_ok ? t.ref.nees.back() : 0.0,
        cr.refinement.extrinsics.phi,
        cr.refinement.extrinsics.rho,
        cr.refinement.extrinsics.psi,
        cr.refinement.merges.size(),
        wrong,
        cr.refinement.num_splits);
  if (std::getenv("VERBOSE"))
    std::printf(
        "   cost %.1f -> %.1f, %d iterations, %d bearings, %d rejected, %zu guarded, %d "
        "features, filter joins %zu, filter tracks %zu\n",
        cr.refinement.initial_cost,
        cr.refinement.final_cost,
        cr.refinement.iterations,
        cr.refinement.num_bearings,
        cr.refinement.num_rejected,
        cr.refinement.guarded.size(),
        cr.refinement.num_features,
        cr.filter.joins.size(),
        cr.filter.tracks.size());
}

// Run r: the filter (with --refine, the tool's pipeline calib::calibrate: the filter, the
// refinement, and the noise checks of the filter (its tracks as its window split them) and of
// the refinement; the model's covariances are kept aside; the filter is run once either way).
void run_once(
    int r, const Args& a, SyntheticRunOptions& so, const CalibrationOptions& fo, Totals& t) {
  so.seed = a.seed + r;
  const SyntheticRun run = make_synthetic_run(so);
  CalibrationResult cr;
  if (a.refine) {
    CalibrationOptions co = fo;
    co.refinement.enabled = true;
    co.association.join_pieces = fo.association.join_pieces && a.merge;
    co.noise_check.lower_level = a.lower_level;
    cr = calibrate(run.run, co);
  }
  const FilterResult fr = a.refine ? cr.filter : run_filter(run.run, fo);
  t.filt.add(
      fr.extrinsics, a.refine ? cr.noise_check.filter_model_covariance : fr.covariance, run.truth);
  if (std::getenv("MISSING")) print_missing_tracks(run, fr);
  if (std::getenv("WINDOW_NEES") && fr.window_frames > 0) print_window_nees(run, fr, t.filt);
  if (std::getenv("VERBOSE") && !t.filt.nees.empty())
    std::printf("run %d: nees %.1f  phi %.4f rho %.4f psi %.4f\n",
                r,
                t.filt.nees.back(),
                fr.extrinsics.phi,
                fr.extrinsics.rho,
                fr.extrinsics.psi);
  add_crlb(run, fo, a, t);
  if (a.refine) add_refinement(r, run, cr, t);
}

// The settings and the Cramer-Rao bounds (RMS over runs).
void print_settings_and_bounds(const Args& a, const CalibrationOptions& fo, const Totals& t) {
  const int runs = a.runs;
  std::printf(
      "trajectory %s, bearing noise %.4f deg + per line %.4f (model %.4f + %.4f), init %s, "
      "bootstrap %.2f rad, K inflation %.1f, iterations %d, track break probability %.2f, runs "
      "%d from seed %llu\n",
      a.trajectory.c_str(),
      a.sigma_deg,
      a.bias_deg,
      rad2deg(fo.noise.bearing_sigma),
      rad2deg(fo.noise.track_bias_sigma),
      a.init.c_str(),
      a.bootstrap,
      a.inflation,
      a.iterations,
      a.break_probability,
      runs,
      static_cast<unsigned long long>(a.seed));
  const Eigen::Vector3d crlb = (t.crlb_sq / runs).cwiseSqrt();
  std::printf(
      "CRLB (RMS over runs): phi %.3f deg  rho %.2f mm  psi %.3f deg  yaw %.4f deg  "
      "position %.2f mm\n",
      rad2deg(crlb(0)),
      1e3 * crlb(1),
      rad2deg(crlb(2)),
      rad2deg(std::sqrt(t.crlb_yaw_sq / runs)),
      1e3 * std::sqrt(t.crlb_pos_sq / runs));
  if (a.break_probability > 0.0) {
    const Eigen::Vector3d j = (t.crlb_joined_sq / runs).cwiseSqrt();
    std::printf("CRLB with each line's pieces joined: phi %.3f deg  rho %.2f mm  psi %.3f deg\n",
                rad2deg(j(0)),
                1e3 * j(1),
                rad2deg(j(2)));
    if (a.refine && !t.ref.nees.empty())
      std::printf("refinement RMS / that bound: phi %.2f  rho %.2f  psi %.2f\n",
                  t.ref.rms()(0) / j(0),
                  t.ref.rms()(1) / j(1),
                  t.ref.rms()(2) / j(2));
  }
}

// The tables: filter, refinement, joins, and the estimates after the noise check.
void print_tables(const Args& a, const Totals& t) {
  const int runs = a.runs;
  const Eigen::Vector3d crlb = (t.crlb_sq / runs).cwiseSqrt();
  const double crlb_yaw = std::sqrt(t.crlb_yaw_sq / runs);
  print("filter", t.filt, crlb, crlb_yaw);
  if (a.refine) print("filter + refinement", t.ref, crlb, crlb_yaw);
  if (a.refine && t.filter_joins > 0)
    std::printf("filter: %d new tracks joined to a feature, %d of them to another line\n",
                t.filter_joins,
                t.filter_wrong);
  if (a.refine && t.all_merges > 0)
    std::printf("refinement: %d pieces of tracks joined, %d of them to another line\n",
                t.all_merges,
                t.wrong_merges);
  if (a.refine && !t.scales.empty()) {
    std::vector<double> scales = t.scales;
    double ms = 0;
    for (double v : scales) ms += v;
    std::sort(scales.begin(), scales.end());
    std::printf(
        "noise check (refinement's): scale mean %.3f, quartiles %.3f %.3f %.3f; "
        "covariance changed in %d runs (filter's: %d)\n",
        ms / scales.size(),
        scales[scales.size() / 4],
        median(scales),
        scales[3 * scales.size() / 4],
        t.applied,
        t.filter_applied);
    print("filter, checked", t.filt_checked, crlb, crlb_yaw);
    print("refinement, checked", t.ref_checked, crlb, crlb_yaw);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = parse_args(argc, argv);
  SyntheticRunOptions so = synthetic_options(a);
  const CalibrationOptions fo = filter_options(a, so);
  Totals t;
  Progress progress("monte carlo", a.runs);
  for (int r = 0; r < a.runs; ++r) {
    run_once(r, a, so, fo, t);
    progress.update(r + 1);
  }
  progress.finish();
  print_settings_and_bounds(a, fo, t);
  print_tables(a, t);
  return 0;
}
