#include "calib/window.hpp"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <limits>

#include "calib/association.hpp"
#include "calib/batch_factors.hpp"
#include "calib/batch_point.hpp"
#include "calib/batch_problem.hpp"
#include "calib/serial_sparse_algebra.hpp"
#include "omnivert/calib/flow_yaw.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/track_ids.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

using namespace internal;

namespace internal {

void WindowTracks::index(const CalibrationRun& window) {
  first_frame.clear();
  last_frame.clear();
  count.clear();
  for (int k = 0; k < static_cast<int>(window.frames.size()); ++k)
    for (const BearingObservation& o : window.frames[k].observations) {
      if (!count[o.track_id]++) first_frame[o.track_id] = k;
      last_frame[o.track_id] = k;
    }
}

int WindowIds::tracker_id(int id) const {
  const auto it = renamed.find(id);
  return it != renamed.end() ? it->second : id;
}

int WindowIds::of_bearing(int id, int frame) const {
  const auto it = bearings.find({id, frame});
  return it != bearings.end() ? it->second : tracker_id(id);
}

WindowIds window_ids(const CalibrationRun& solved,
                     const CalibrationRun& window_in,
                     std::map<int, int> renamed) {
  WindowIds ids;
  ids.renamed = std::move(renamed);
  for (std::size_t k = 0; k < solved.frames.size() && k < window_in.frames.size(); ++k) {
    const auto& a = solved.frames[k].observations;
    const auto& o = window_in.frames[k].observations;
    for (std::size_t i = 0; i < a.size() && i < o.size(); ++i)
      ids.bearings[{a[i].track_id, static_cast<int>(k)}] = o[i].track_id;
  }
  return ids;
}

}  // namespace internal

namespace {

// A track not seen for more than max_missed_frames has ended, in the window as in the filter
// after it (which marginalises it, and takes a later bearing with its id for a new feature):
// the bearings after such a gap are another track here too. The window cannot know which
// lines are still in view after their tracks ended, so the crossing guard cannot protect a
// bearing after a long gap: a lone bearing pulled towards a line that crossed meanwhile made
// the window overconfident (BootstrapWindowEndsATrackAfterALongGap). `gap_origin`: new id ->
// the tracker's.
CalibrationRun split_at_gaps(const CalibrationRun& window_in,
                             const CalibrationOptions& options,
                             std::map<int, int>* gap_origin) {
  std::map<int, int> last;
  std::vector<TrackSplit> gaps;
  for (int k = 0; k < static_cast<int>(window_in.frames.size()); ++k)
    for (const BearingObservation& o : window_in.frames[k].observations) {
      const auto it = last.find(o.track_id);
      // (The filter marginalises a track after the frame that is max_missed_frames + 1 past
      // its last bearing.)
      if (it != last.end() && k - it->second > options.association.max_missed_frames + 1)
        gaps.emplace_back(o.track_id, k);
      last[o.track_id] = k;
    }
  return split_tracks(window_in, gaps, gap_origin);
}

// The window's problem: odometry and bearings (build, with the decisions' options), the
// priors on the extrinsics (options.prior.mean) and on each track's inverse depth along its first
// ray; and its solve.
struct WindowProblem {
  WindowProblem(const CalibrationOptions& options, const CalibrationRun& window)
      : options(options), window(window) {
    const double q_lo = 1.0 / options.filter.max_feature_distance;
    const double q_hi = 1.0 / options.filter.min_feature_distance;
    q0 = 0.5 * (q_lo + q_hi);
    sigma_q = 0.25 * (q_hi - q_lo);
    // The decisions (crossings, outliers, joins, splits) under the bearing's whole error; the
    // per-track bias, when modelled, in the final solve (association_options).
    decisions = association_options(options);
    decisions.association.min_track_length = 2;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;  // as the refinement
    so.max_num_iterations = 100;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    tracks.index(window);
  }

  Built with_priors(Built b) const {
    if (b.features.empty()) return b;
    b.problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<ExtrinsicsPrior, 3, 3>(
            new ExtrinsicsPrior{options.prior.mean.vec(), options.prior.sigma.cwiseInverse()}),
        nullptr,
        b.ex.data());
    for (auto& [id, f] : b.features)
      b.problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<InverseDepthPrior, 1, 3, 2, 3>(new InverseDepthPrior{
              q0, 1.0 / (options.filter.bootstrap_depth_prior_scale * sigma_q)}),
          nullptr,
          b.poses[tracks.first_frame.at(id)].data(),
          f.data(),
          b.ex.data());
    return b;
  }

  Built build_from(const CalibrationRun& w, const BatchPoint& start) const {
    return with_priors(build(w, decisions, start, /*robust=*/false));
  }

  // Solved from extrinsics ex0: dead-reckoned poses, each track on its first ray at depth
  // 1/q0. false when no track has two bearings.
  bool solve_from(const Extrinsics& ex0, Built* out, ceres::Solver::Summary* sum) const {
    BatchPoint start;
    start.poses = dead_reckoning(window, options.robot.wheel_base);
    start.extrinsics = ex0;
    for (const auto& [id, k] : tracks.first_frame) {
      for (const BearingObservation& o : window.frames[k].observations) {
        if (o.track_id != id) continue;
        const Eigen::Vector3d& p = start.poses[k];
        const Vec2 C =
            p.head<2>() + ex0.rho * Vec2(std::cos(p(2) + ex0.phi), std::sin(p(2) + ex0.phi));
        const double dir = p(2) + ex0.phi + ex0.psi + o.beta;
        start.features[id] = C + Vec2(std::cos(dir), std::sin(dir)) / q0;
        break;
      }
    }
    Built b = build_from(window, start);
    if (b.features.empty()) return false;
    ceres::Solve(so, b.problem.get(), sum);
    *out = std::move(b);
    return true;
  }

  // The association loop of the window: a feature needs one bearing (with its depth prior),
  // a window left without features fails, the tracks are indexed again with each rebuild.
  AssociationSetup association_setup(const std::map<int, int>& gap_origin,
                                     ceres::Solver::Summary* summary) {
    AssociationSetup s;
    s.options = &options;
    s.min_bearings = 1;
    s.join_pieces = options.association.join_pieces;
    s.split = options.association;
    s.base_origin = gap_origin;
    s.stop_when_empty = true;
    s.rebuild = [this](const CalibrationRun& w, const BatchPoint& at) {
      tracks.index(w);
      return build_from(w, at);
    };
    s.solve = [this, summary](Built* b) { ceres::Solve(so, b->problem.get(), summary); };
    return s;
  }

  const CalibrationOptions& options;
  const CalibrationRun& window;
  double q0 = 0.0, sigma_q = 0.0;  // the inverse-depth prior
  CalibrationOptions decisions;
  ceres::Solver::Options so;
  WindowTracks tracks;  // of the run last built
};

// Levenberg-Marquardt from the prior alone can end in a local minimum, 15 degrees off in phi,
// from which the filter never recovers (docs/theory/window.md#starts). The window is solved
// from the prior and from starts with phi moved by +-0.5 and +-1 rad (psi moved the other
// way, keeping the camera yaw, which the bearings fix first).
// A camera mounted far from the prior's yaw (80-110 degrees) leaves every start of the
// prior's camera yaw far off: none converges in 100 iterations, and which one wins is chance.
// Where the bearings' flow (camera_yaw_from_flow) puts the camera yaw more than kFlowYawGap
// from the prior's, the same starts are solved at the flow's yaw as well. The flow's own
// error from pixels is 0.03-0.10 rad on average, 0.21 at most, over 60 runs of the paper's
// mounting: those runs keep their five starts (test: WindowStarts.CameraYawFromTheBearingsFlow
// and the rendered runs of CalibrationRegression, tests/pipeline).
std::vector<Extrinsics> window_starts(const CalibrationOptions& options,
                                      const CalibrationRun& window) {
  constexpr double kFlowYawGap = 0.35;  // rad
  const double prior_yaw = options.prior.mean.phi + options.prior.mean.psi;
  const double flow_yaw = camera_yaw_from_flow(window, options.robot.wheel_base);
  const bool flow_starts =
      std::isfinite(flow_yaw) && std::abs(wrap_angle(flow_yaw - prior_yaw)) > kFlowYawGap;
  spdlog::debug("window: camera yaw from the bearings' flow {:.4f} rad (prior {:.4f}){}",
                flow_yaw,
                prior_yaw,
                flow_starts ? ": starts at both" : "");
  constexpr std::array<double, 5> kStarts{0.0, -0.5, 0.5, -1.0, 1.0};
  const int per_yaw =
      std::min<int>(options.filter.bootstrap_starts, static_cast<int>(kStarts.size()));
  const int starts = flow_starts ? 2 * per_yaw : per_yaw;
  std::vector<Extrinsics> out;
  for (int i = 0; i < starts; ++i) {
    const double d = kStarts[static_cast<std::size_t>(i % per_yaw)];
    Extrinsics ex0 = options.prior.mean;
    if (i >= per_yaw) ex0.psi = wrap_angle(flow_yaw - ex0.phi);
    ex0.phi += d;
    ex0.psi -= d;
    out.push_back(ex0);
  }
  return out;
}

// The window solved from each start; the start with the lowest cost is kept (costs compared
// before outliers are removed, on the same residuals). The starts are independent problems
// and run in threads; the choice does not depend on their order of completion (lowest cost,
// ties to the earlier start). false (reason in *why) when a start has no track with two
// bearings or no solve is usable.
bool solve_best_start(const WindowProblem& problem,
                      const std::vector<Extrinsics>& starts,
                      Built* b,
                      ceres::Solver::Summary* summary,
                      std::string* why) {
  struct Start {
    Built built;
    ceres::Solver::Summary summary;
    Extrinsics from;
    bool ok = false;
  };
  std::vector<Start> runs(starts.size());
  {
    std::vector<std::future<void>> pending;
    for (std::size_t i = 0; i < starts.size(); ++i)
      pending.push_back(std::async(std::launch::async, [&, i] {
        const SerialSparseAlgebra serial;  // each start's thread: one OpenMP thread in CHOLMOD
        Start& r = runs[i];
        r.from = starts[i];
        r.ok = problem.solve_from(starts[i], &r.built, &r.summary);
      }));
    for (auto& p : pending) p.get();
  }
  bool have = false;
  double best_cost = std::numeric_limits<double>::infinity();
  for (Start& r : runs) {
    if (!r.ok) {
      *why = "no track with two bearings in the window";
      return false;
    }
    spdlog::debug(
        "window start ({:.3f}, {:.3f}): cost {:.6g}, phi {:.4f} rho {:.4f} psi {:.4f} ({})",
        r.from.phi,
        r.from.psi,
        r.summary.final_cost,
        r.built.ex[0],
        r.built.ex[1],
        r.built.ex[2],
        ceres::TerminationTypeToString(r.summary.termination_type));
    if (r.summary.IsSolutionUsable() && r.summary.final_cost < best_cost) {
      best_cost = r.summary.final_cost;
      *b = std::move(r.built);
      *summary = r.summary;
      have = true;
    }
  }
  if (!have) *why = "window solve failed: " + summary->BriefReport();
  return have;
}

// The association's end as the window's failure.
std::string association_failure(AssociationEnd end) {
  return end == AssociationEnd::kNoTrack ? "no track with two bearings in the window"
                                         : "no track left in the window where lines do not cross";
}

}  // namespace

// Where the window is most of the run (the paper trajectory turns 1.5 rad only at frame 87 of
// 114; a zigzag never turns 1.5 rad away from its start heading), the filter's estimate is the
// window's: the window joins the pieces of one line and splits the tracks that slipped onto a
// neighbouring line as the refinement does (associate;
// docs/theory/association.md#pieces-of-one-line, "Tracks that slipped onto a neighbouring line"). A
// joined piece takes the id of its line's first piece, the later part of a split track a new id;
// the filter continues each under the tracker's ids (BootstrapDetails).
bool bootstrap_filter_state(const CalibrationRun& window_in,
                            const CalibrationOptions& options,
                            FilterState* state,
                            std::string* why,
                            BootstrapDetails* details) {
  std::string reason;
  auto fail = [why](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  std::map<int, int> gap_origin;
  const CalibrationRun window = split_at_gaps(window_in, options, &gap_origin);
  const int W = static_cast<int>(window.frames.size());
  if (W < 2) return fail("window too short");
  const SerialSparseAlgebra serial;  // the solves on this thread (the starts' threads: their own)
  WindowProblem problem(options, window);
  ceres::Solver::Summary summary;
  Built b;
  if (!solve_best_start(problem, window_starts(options, window), &b, &summary, &reason))
    return fail(reason);
  Association association;
  if (const AssociationEnd end =
          associate(&b, window, problem.association_setup(gap_origin, &summary), &association);
      end != AssociationEnd::kDone)
    return fail(association_failure(end));
  if (options.noise.track_bias_sigma > 0.0) {
    b = problem.with_priors(final_with_bias(association.solved(), b, options, false, 1));
    if (b.features.empty()) return fail(association_failure(AssociationEnd::kNoTrackLeft));
    ceres::Solve(problem.so, b.problem.get(), &summary);
  }
  if (!summary.IsSolutionUsable()) return fail("window solve failed: " + summary.BriefReport());
  spdlog::debug("window solved: {} frames, cost {:.6g}, phi {:.4f} rho {:.4f} psi {:.4f}",
                W,
                summary.final_cost,
                b.ex[0],
                b.ex[1],
                b.ex[2]);
  const WindowIds ids =
      window_ids(association.solved(), window_in, tracker_ids(gap_origin, association.origin));
  if (!window_to_filter(
          b, options, W, problem.tracks, ids, association, gap_origin, state, details, &reason))
    return fail(reason);
  return true;
}

}  // namespace omnivert::calib
