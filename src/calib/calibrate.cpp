#include "omnivert/calib/calibrate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <spdlog/spdlog.h>
#include <Eigen/Cholesky>

#include "calib/batch_point.hpp"
#include "calib/refine_steps.hpp"
#include "calib/updater.hpp"
#include "core/parallel.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

namespace {
// The run without the given (track id, frame) bearings: those guarded where lines cross and
// those refused as outliers.
CalibrationRun without_bearings(const CalibrationRun& run,
                                const std::vector<BearingKey>& guarded,
                                const std::vector<BearingKey>& rejected) {
  if (guarded.empty() && rejected.empty()) return run;
  std::map<int, std::set<int>> by_frame;  // frame -> track ids
  for (const auto& [id, k] : guarded) by_frame[k].insert(id);
  for (const auto& [id, k] : rejected) by_frame[k].insert(id);
  CalibrationRun out = run;
  for (const auto& [k, ids] : by_frame) {
    if (k < 0 || k >= static_cast<int>(out.frames.size())) continue;
    auto& obs = out.frames[static_cast<std::size_t>(k)].observations;
    obs.erase(
        std::remove_if(obs.begin(),
                       obs.end(),
                       [&ids](const BearingObservation& o) { return ids.count(o.track_id) > 0; }),
        obs.end());
  }
  return out;
}

// CalibrationOptions::noise_check.lower_max_joins: whether "less noise" may be applied to a
// check over check.clusters tracks after `joins` pieces of lines were joined.
bool lower_side_applies(const NoiseCheckOptions& nc,
                        std::size_t joins,
                        const BatchNoiseCheck& check) {
  return nc.lower_max_joins >= 0.0 &&
         static_cast<double>(joins) <= nc.lower_max_joins * check.clusters;
}

// The covariance "less noise" reports: the bearings' share shrunk only as far as the test allows,
// to the largest variance factor it does not reject at `lower_level`, scale / (chi2(lower_level,
// G) / G) with G the tracks checked (below 1 exactly where the verdict is "less noise"), not to
// the point estimate `scale`. Under the model `scale` is itself about chi-square(G) / G: shrunk to
// it, the runs the test flags by chance become overconfident (docs/theory/noise-check.md).
// `reported` is the covariance before, whose bearings' share is the check's model's. None when
// the result is not positive definite (the covariance is then kept).
std::optional<Eigen::Matrix3d> less_noise_covariance(const BatchNoiseCheck& check,
                                                     double lower_level,
                                                     const Eigen::Matrix3d& reported) {
  const double bound = check.scale / noise_check_lower_limit(check.clusters, lower_level);
  const double share = (1.0 - bound) / (1.0 - check.scale);  // of the shrink to `scale`
  Eigen::Matrix3d c = reported + share * (check.covariance - check.model_covariance);
  c = 0.5 * (c + c.transpose());
  if (!c.allFinite() || Eigen::LLT<Eigen::Matrix3d>(c).info() != Eigen::Success)
    return std::nullopt;
  return c;
}

// tr(model^-1 covariance) / 3: the variance factor a reported covariance stands for.
double factor_of(const Eigen::Matrix3d& model, const Eigen::Matrix3d& covariance) {
  const Eigen::LDLT<Eigen::Matrix3d> m(model);
  if (m.info() != Eigen::Success) return 0.0;
  const double f = m.solve(covariance).trace() / 3.0;
  return std::isfinite(f) && f > 0.0 ? f : 0.0;
}

// Each stage's time, on the log's debug level (omnivert -v).
class StageTimer {
 public:
  // Logs and returns the time since the last lap [s].
  double lap(const char* stage) {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - t_).count();
    spdlog::debug("calibrate: {} {:.2f} s", stage, seconds);
    t_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point t_ = std::chrono::steady_clock::now();
};

// The refinement (CalibrationOptions::refinement) from the filter's point, and Sec. 8.1 at the best
// estimate of the trajectory, the features and the extrinsics, on the bearings the estimate
// used.
void refine_and_analyse(const CalibrationRun& run,
                        const CalibrationOptions& options,
                        const BatchPoint& filter_point,
                        StageTimer* timer,
                        CalibrationResult* r) {
  BatchPoint at = filter_point;
  // Sec. 8.1 on the bearings the estimate used: those left out where lines cross
  // (CalibrationOptions::association.crossing_guard) do not follow eq. (30)'s model, and those the
  // gate refused are taken for outliers; neither carries information the estimators use. Pieces of
  // one line that the filter joined (CalibrationOptions::association.join_pieces) are one feature
  // there.
  CalibrationRun analysed =
      join_tracks(without_bearings(run, r->filter.guarded, r->filter.rejected), r->filter.joins);
  if (options.refinement.enabled) {
    r->refinement = refine_batch(run, options, at);
    r->refined = true;
    r->covariance_from_information = r->refinement.covariance_from_information;
    at = r->refinement.solution;
    // The same problem (split where the refinement split the tracks), without the guarded
    // bearings and those the refinement rejected as outliers: the bound is that of the
    // problem the estimate solved (with the outliers' information counted, the bounds come
    // out small: CalibrationFilter.RefusedBearingsAreListedAndLeftOutOfTheBound).
    analysed = without_bearings(r->refinement.renamed() ? r->refinement.solved_run : run,
                                r->refinement.guarded,
                                r->refinement.rejected);
    r->seconds.refinement = timer->lap("refinement");
  }
  r->observability = analyse_observability(analysed, options, at);
  r->seconds.observability = timer->lap("observability");
  if (r->refined && !r->refinement.covariance_ok && r->observability.all_determined() &&
      r->observability.crlb_covariance.allFinite()) {
    // ceres::Covariance gives up on badly scaled problems (poses in metres, bearings whitened
    // by a small sigma); the marginal Fisher information at the same solution is the same
    // quantity, computed with the Schur complement.
    r->refinement.covariance = r->observability.crlb_covariance;
    r->refinement.covariance_ok = true;
    r->covariance_from_information = true;
  }
}

// The overall variance ratio tr(model^-1 checked) / 3 of a noise check; 0 when it failed.
double ratio_of(const BatchNoiseCheck& n) {
  return n.ok ? factor_of(n.model_covariance, n.covariance) : 0.0;
}

// Whether the filter's noise check is the refinement's own: with no splits or joins anywhere,
// the refinement already solved the filter's problem (known only once it has run).
bool filter_check_may_be_the_refinements(const CalibrationOptions& options, const FilterResult& f) {
  return options.refinement.enabled && f.splits.empty() && f.joins.empty();
}

// The noise check of the filter: on its own tracks, joined where it joined them
// (FilterResult::joins) and split only where its window split them (FilterResult::splits),
// each part starting at the track's filter estimate (after the window the filter treats a
// track that slipped onto a neighbouring line as one feature, and the check should see
// that). It needs nothing of the refinement, so it may run beside it.
BatchNoiseCheck filter_noise_check(const CalibrationRun& run,
                                   const CalibrationOptions& options,
                                   const BatchPoint& filter_point,
                                   const FilterResult& filter) {
  CalibrationOptions unsplit = options;
  unsplit.association.split_chi2 = 0.0;
  unsplit.association.join_pieces = false;
  std::map<int, int> origin;
  const CalibrationRun filter_run =
      split_tracks(join_tracks(run, filter.joins), filter.splits, &origin);
  BatchPoint start = filter_point;
  for (const auto& [id, tracker] : origin)
    if (const auto it = filter_point.features.find(tracker); it != filter_point.features.end())
      start.features[id] = it->second;
  return internal::refine_batch(filter_run, unsplit, start, {/*covariance=*/false}).noise;
}

// The filter's noise check applied to its covariance: scaled by the ratio when the check
// shows more noise, the bearings' share shrunk when it shows less where the tracker kept its
// lines (CalibrationOptions::noise_check).
void apply_filter_noise(const NoiseCheckOptions& nc, CalibrationResult* r) {
  const double ratio = ratio_of(r->noise_check.filter_check);
  if (!(ratio > 0.0)) return;
  r->noise_check.checked = true;
  r->noise_check.check = r->noise_check.filter_check;
  r->noise_check.filter_verdict =
      noise_check_verdict(r->noise_check.filter_check, nc.level, nc.lower_level);
  r->noise_check.verdict = r->noise_check.filter_verdict;
  auto apply = [&](const Eigen::Matrix3d& covariance) {
    r->filter.covariance = covariance;
    r->noise_check.filter_applied = r->noise_check.applied = true;
    r->noise_check.filter_ratio = r->noise_check.ratio = ratio;
  };
  if (r->noise_check.filter_verdict == NoiseVerdict::kMoreNoise) {
    apply(r->filter.covariance * ratio);
  } else if (r->noise_check.filter_verdict == NoiseVerdict::kLessNoise &&
             lower_side_applies(nc, r->filter.joins.size(), r->noise_check.filter_check)) {
    const Eigen::Matrix3d before = r->filter.covariance;
    if (const auto shrunk =
            less_noise_covariance(r->noise_check.filter_check, nc.lower_level, before)) {
      apply(*shrunk);
      r->noise_check.filter_ratio = r->noise_check.ratio = factor_of(before, *shrunk);
    }
  }
}

// The refinement's noise check (at its solution) applied to its covariance: the checked
// covariance where the check shows more noise, or less where few pieces of lines were joined.
void apply_refinement_noise(const NoiseCheckOptions& nc, CalibrationResult* r) {
  r->noise_check.checked = false;
  r->noise_check.applied = false;
  r->noise_check.verdict = NoiseVerdict::kAgrees;
  r->noise_check.ratio = 1.0;
  const double ratio = ratio_of(r->refinement.noise);
  if (!(ratio > 0.0)) return;
  r->noise_check.checked = true;
  r->noise_check.check = r->refinement.noise;
  r->noise_check.verdict = noise_check_verdict(r->noise_check.check, nc.level, nc.lower_level);
  if (r->noise_check.verdict == NoiseVerdict::kMoreNoise) {
    r->noise_check.applied = true;
    r->noise_check.ratio = ratio;
    r->refinement.covariance = r->noise_check.check.covariance;
  } else if (r->noise_check.verdict == NoiseVerdict::kLessNoise &&
             lower_side_applies(nc, r->refinement.merges.size(), r->noise_check.check)) {
    const Eigen::Matrix3d model = r->noise_check.check.model_covariance;
    if (const auto shrunk = less_noise_covariance(r->noise_check.check, nc.lower_level, model)) {
      r->noise_check.applied = true;
      r->noise_check.ratio = factor_of(model, *shrunk);
      r->refinement.covariance = *shrunk;
    }
  }
}

CalibrationResult calibrate_once(const CalibrationRun& run, const CalibrationOptions& options) {
  const NoiseCheckOptions& nc = options.noise_check;
  CalibrationResult r;
  r.model.bearing_sigma = options.noise.bearing_sigma;
  r.model.track_bias_sigma = options.noise.track_bias_sigma;
  r.noise_check.level = nc.level;
  r.noise_check.lower_level = nc.lower_level;
  StageTimer timer;
  r.filter = run_filter(run, options);
  r.seconds.filter = timer.lap("filter");
  const BatchPoint filter_point = batch_point_from_filter(run, options, r.filter);
  // The filter's noise check on its own tracks does not wait for the refinement: with a
  // second thread it runs beside it (the same numbers; spent for nothing when the trajectory
  // leaves the extrinsics undetermined).
  // The check reports no progress: it runs on another thread, or after the refinement.
  CalibrationOptions quiet = options;
  quiet.progress = nullptr;
  std::future<BatchNoiseCheck> beside;
  if (nc.enabled && !filter_check_may_be_the_refinements(options, r.filter) &&
      resolve_threads(options.threads) > 1)
    beside = std::async(std::launch::async, [&run, &quiet, &filter_point, &r] {
      return filter_noise_check(run, quiet, filter_point, r.filter);
    });
  refine_and_analyse(run, options, filter_point, &timer, &r);
  r.noise_check.filter_model_covariance = r.filter.covariance;
  r.noise_check.refinement_model_covariance = r.refinement.covariance;
  if (nc.enabled && r.observability.all_determined()) {
    // How large the errors really are, measured by the data (docs/theory/noise-check.md): at a
    // batch solution, the errors of each track summed before squaring. The
    // filter is checked on its own tracks, the refinement on the problem it solved (tracks
    // split). A covariance is replaced by the checked one only when the check shows more
    // noise than the model allows (noise_check_verdict): with 10-15 tracks one run's scale
    // is uncertain, and applied always it made the refinement's NEES worse where the model
    // is right (synthetic 0.3 degree, 50 runs: 3.50 -> 5.18). Less noise is applied only
    // where few pieces of lines were joined (CalibrationOptions::noise_check,
    // noise_check_lower_max_joins).
    if (beside.valid())
      r.noise_check.filter_check = beside.get();
    else if (r.refined && !r.refinement.renamed() &&
             filter_check_may_be_the_refinements(options, r.filter))
      r.noise_check.filter_check = r.refinement.noise;
    else
      r.noise_check.filter_check = filter_noise_check(run, quiet, filter_point, r.filter);
    r.seconds.noise_check = timer.lap("the filter's noise check");
    apply_filter_noise(nc, &r);
    if (r.refined && r.refinement.covariance_ok) apply_refinement_noise(nc, &r);
  }
  r.extrinsics = r.filter.extrinsics;
  r.covariance = r.filter.covariance;
  r.source = Estimator::kFilter;
  if (r.refined && r.refinement.covariance_ok) {
    r.extrinsics = r.refinement.extrinsics;
    r.covariance = r.refinement.covariance;
    r.source = Estimator::kRefinement;
  }
  return r;
}
}  // namespace

CalibrationResult result_of_filter(const CalibrationRun& run,
                                   const CalibrationOptions& options,
                                   FilterResult filter) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  CalibrationOptions o = options;
  o.refinement.enabled = false;
  CalibrationResult r;
  r.model.bearing_sigma = o.noise.bearing_sigma;
  r.model.track_bias_sigma = o.noise.track_bias_sigma;
  r.noise_check.level = o.noise_check.level;
  r.noise_check.lower_level = o.noise_check.lower_level;
  r.filter = std::move(filter);
  StageTimer timer;
  const BatchPoint filter_point = batch_point_from_filter(run, o, r.filter);
  refine_and_analyse(run, o, filter_point, &timer, &r);
  r.noise_check.filter_model_covariance = r.filter.covariance;
  r.extrinsics = r.filter.extrinsics;
  r.covariance = r.filter.covariance;
  r.source = Estimator::kFilter;
  return r;
}

const char* estimator_name(Estimator e) {
  return e == Estimator::kRefinement ? "refinement" : "filter";
}

CalibrationResult calibrate(const CalibrationRun& run, const CalibrationOptions& options) {
  return calibrate_once(run, options);
}

namespace {
// A model sigma scaled as the noise check found the errors; NaN when not checked.
double checked_sigma(const CalibrationResult& r, double sigma) {
  return r.noise_check.check.ok ? sigma * std::sqrt(r.noise_check.check.scale)
                                : std::numeric_limits<double>::quiet_NaN();
}
}  // namespace

double effective_bearing_sigma(const CalibrationResult& r) {
  return checked_sigma(r, r.model.bearing_sigma);
}

double effective_track_bias_sigma(const CalibrationResult& r) {
  return checked_sigma(r, r.model.track_bias_sigma);
}

namespace {
std::string num(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  std::ostringstream s;
  s << std::setprecision(10) << v;
  return s.str();
}

void commit_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw InputError(path, 0, "cannot write the file");
    f << text;
    f.flush();
    if (!f) throw InputError(path, 0, "cannot write the file");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path, 0, "cannot move the written file into place");
  }
}
}  // namespace

void write_extrinsics_yaml(const std::string& path, const CalibrationResult& r) {
  const Extrinsics& e = r.extrinsics;
  const Eigen::Matrix3d& C = r.covariance;
  const bool cov_ok = C.allFinite() && e.vec().allFinite();
  std::ostringstream y;
  y << "# Camera-to-odometry extrinsics (omnivert calibrate). Camera centre at\n"
       "# rho (cos phi, sin phi) in the robot frame, camera x-axis rotated by phi + psi.\n";
  y << "phi: " << num(e.phi) << "\nrho: " << num(e.rho) << "\npsi: " << num(e.psi) << "\n";
  for (int i = 0; i < 3; ++i) {
    static const char* names[] = {"sigma_phi", "sigma_rho", "sigma_psi"};
    y << names[i] << ": " << num(cov_ok ? std::sqrt(C(i, i)) : NAN) << "\n";
  }
  y << "covariance: [";
  for (int i = 0; i < 9; ++i) y << (i ? ", " : "") << num(cov_ok ? C(i / 3, i % 3) : NAN);
  y << "]\n";
  const Eigen::Vector2d p = e.position();
  y << "x: " << num(p(0)) << "\ny: " << num(p(1)) << "\nyaw: " << num(e.yaw()) << "\n";
  const Eigen::Matrix4d T = e.T_base_cam();
  y << "T_base_cam:\n";
  for (int i = 0; i < 4; ++i) {
    y << "  - [";
    for (int j = 0; j < 4; ++j) y << (j ? ", " : "") << num(T(i, j));
    y << "]\n";
  }
  const ObservabilityReport& o = r.observability;
  y << "observable: " << (o.all_determined() ? "true" : "false") << "\n";
  y << "crlb_phi: " << num(o.phi.crlb) << "\ncrlb_rho: " << num(o.rho.crlb)
    << "\ncrlb_psi: " << num(o.psi.crlb) << "\ncrlb_yaw: " << num(o.yaw.crlb) << "\n";
  y << "source: " << estimator_name(r.source) << "\n";
  std::string msg = o.message;
  for (char& c : msg)
    if (c == '"') c = '\'';
  y << "message: \"" << msg << "\"\n";
  commit_file(path, y.str());
}

void write_states_csv(const std::string& path, const std::vector<FrameEstimate>& history) {
  std::ostringstream s;
  s << "frame,phi,rho,psi,sigma_phi,sigma_rho,sigma_psi,features,updates,rejected,new,guarded\n";
  s << std::setprecision(10);
  for (const FrameEstimate& h : history) {
    s << h.frame << "," << num(h.extrinsics.phi) << "," << num(h.extrinsics.rho) << ","
      << num(h.extrinsics.psi);
    for (int i = 0; i < 3; ++i) s << "," << num(std::sqrt(std::max(h.covariance(i, i), 0.0)));
    s << "," << h.num_features << "," << h.num_updates << "," << h.num_rejected << "," << h.num_new
      << "," << h.num_guarded << "\n";
  }
  commit_file(path, s.str());
}

}  // namespace omnivert::calib
