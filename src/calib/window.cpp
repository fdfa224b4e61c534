#include "calib/window.hpp"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <limits>

#include "calib/association.hpp"
#include "calib/batch_factors.hpp"
#include "calib/batch_problem.hpp"
#include "omnivert/calib/batch_point.hpp"
#include "omnivert/calib/flow_yaw.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/track_ids.hpp"
#include "omnivert/calib/updater.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

using namespace internal;

namespace {

// Central differences of f (a smooth map of the window's variables) at v0, over the variables
// `cols`: d f / d v(cols). Rows in `angle_rows` are angles and their differences are wrapped.
template <typename F>
Eigen::MatrixXd central_jacobian(const F& f,
                                 const Eigen::VectorXd& v0,
                                 const std::vector<int>& cols,
                                 const std::vector<int>& angle_rows) {
  constexpr double h = 1e-6;
  Eigen::MatrixXd J;
  for (std::size_t j = 0; j < cols.size(); ++j) {
    Eigen::VectorXd vp = v0, vm = v0;
    vp(cols[j]) += h;
    vm(cols[j]) -= h;
    Eigen::VectorXd d = f(vp) - f(vm);
    for (int r : angle_rows) d(r) = wrap_angle(d(r));
    if (j == 0) J.resize(d.size(), static_cast<Eigen::Index>(cols.size()));
    J.col(static_cast<Eigen::Index>(j)) = d / (2 * h);
  }
  return J;
}

}  // namespace

bool bootstrap_filter_state(const CalibrationRun& window_in,
                            const Options& options,
                            FilterState* state,
                            std::string* why,
                            BootstrapDetails* details) {
  auto fail = [why](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  // A track not seen for more than max_missed_frames has ended, in the window as in the
  // filter after it (which marginalises it, and takes a later bearing with its id for a new
  // feature): the bearings after such a gap are another track here too. The window cannot
  // know which lines are still in view after their tracks ended, so the crossing guard cannot
  // protect a bearing after a long gap (office paper seed 18 with the crowded lines' bearings
  // left out: tracks 2 and 3 crossed over frames 53-80 with no bearing of either; track 2's
  // lone bearing at frame 74, 0.11 degree off towards the other line, made the window's phi
  // three times too certain and 3 sigma off). `gap_origin`: new id -> the tracker's.
  std::map<int, int> gap_origin;
  const CalibrationRun window = [&] {
    std::map<int, int> last;
    std::vector<std::pair<int, int>> gaps;
    for (int k = 0; k < static_cast<int>(window_in.frames.size()); ++k)
      for (const BearingObservation& o : window_in.frames[k].observations) {
        const auto it = last.find(o.track_id);
        // (The filter marginalises a track after the frame that is max_missed_frames + 1
        // past its last bearing.)
        if (it != last.end() && k - it->second > options.max_missed_frames + 1)
          gaps.emplace_back(o.track_id, k);
        last[o.track_id] = k;
      }
    return split_tracks(window_in, gaps, &gap_origin);
  }();
  const int W = static_cast<int>(window.frames.size());
  if (W < 2) return fail("window too short");
  const double q_lo = 1.0 / options.max_feature_distance;
  const double q_hi = 1.0 / options.min_feature_distance;
  const double q0 = 0.5 * (q_lo + q_hi), sigma_q = 0.25 * (q_hi - q_lo);

  // First and last frame and number of bearings of each track of a window (after splits, of
  // the window with the split parts renamed).
  std::map<int, int> first_frame, last_frame, count;
  auto index_tracks = [&](const CalibrationRun& w) {
    first_frame.clear();
    last_frame.clear();
    count.clear();
    for (int k = 0; k < W; ++k)
      for (const BearingObservation& o : w.frames[k].observations) {
        if (!count[o.track_id]++) first_frame[o.track_id] = k;
        last_frame[o.track_id] = k;
      }
  };
  index_tracks(window);
  // The decisions (crossings, outliers, joins, splits) under the bearing's whole error; the
  // per-track bias, when modelled, in the final solve (association_options).
  Options opt = association_options(options);
  opt.min_track_length = 2;
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;  // as the refinement
  so.max_num_iterations = 100;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;

  // The window's problem from a starting point: odometry and bearings, the priors on the
  // extrinsics (options.prior) and on each track's inverse depth along its first ray.
  BatchOptions window_batch;
  window_batch.lateral_sigma = options.lateral_sigma;
  auto add_window_priors = [&](Built b) {
    if (b.features.empty()) return b;
    b.problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<ExtrinsicsPrior, 3, 3>(
            new ExtrinsicsPrior{options.prior.vec(), options.prior_sigma.cwiseInverse()}),
        nullptr,
        b.ex.data());
    for (auto& [id, f] : b.features)
      b.problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<InverseDepthPrior, 1, 3, 2, 3>(
              new InverseDepthPrior{q0, 1.0 / (options.bootstrap_depth_prior_scale * sigma_q)}),
          nullptr,
          b.poses[first_frame.at(id)].data(),
          f.data(),
          b.ex.data());
    return b;
  };
  auto build_window = [&](const CalibrationRun& w, const BatchPoint& start) {
    Built b = build(w, opt, start, window_batch, /*robust=*/false);
    return add_window_priors(std::move(b));
  };
  // Solved from extrinsics ex0: dead-reckoned poses, each track on its first ray at depth 1/q0.
  auto solve_from = [&](const Extrinsics& ex0, Built* out, ceres::Solver::Summary* sum) {
    BatchPoint start;
    start.poses = dead_reckoning(window, options.wheel_base);
    start.extrinsics = ex0;
    for (const auto& [id, k] : first_frame) {
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
    Built b = build_window(window, start);
    if (b.features.empty()) return false;
    ceres::Solve(so, b.problem.get(), sum);
    *out = std::move(b);
    return true;
  };
  // Levenberg-Marquardt from the prior alone can end in a local minimum (measured: office,
  // zigzag, seed 11 from phi = 0 ended 15 degrees off in phi, and the filter never recovered;
  // docs/calib.md "Window starts"). The window is solved from the prior and from starts with
  // phi moved by +-0.5 and +-1 rad (psi moved the other way, keeping the camera yaw, which the
  // bearings fix first); the start with the lowest cost is kept. Costs are compared before
  // outliers are removed, on the same residuals.
  // The starts are independent problems and run in threads; the choice does not depend on
  // their order of completion (lowest cost, ties to the earlier start).
  // A camera mounted far from the prior's yaw (session 16: 80-110 degrees, with the truth
  // drawn from the prior's spread) left every start of the prior's camera yaw far off: none
  // converged in 100 iterations, and which one won was chance (corridor zigzag, truth phi
  // -0.915, psi -0.961: the filter ended 33 degrees off in phi, or right, depending on the
  // ninth digit of the bearings). Where the bearings' flow puts the camera yaw more than
  // kFlowYawGap from the prior's, the same five starts are solved at the flow's yaw as well.
  // The flow's own error from pixels: 0.03-0.10 rad on average, 0.21 at most, over 60 runs
  // of the paper's mounting (both worlds and trajectories, seeds 1-15): those runs keep
  // their five starts.
  constexpr double kFlowYawGap = 0.35;  // rad
  const double prior_yaw = options.prior.phi + options.prior.psi;
  const double flow_yaw = camera_yaw_from_flow(window, options.wheel_base);
  const bool flow_starts =
      std::isfinite(flow_yaw) && std::abs(wrap_angle(flow_yaw - prior_yaw)) > kFlowYawGap;
  spdlog::debug("window: camera yaw from the bearings' flow {:.4f} rad (prior {:.4f}){}",
                flow_yaw,
                prior_yaw,
                flow_starts ? ": starts at both" : "");
  Built b;
  bool have = false;
  double best_cost = std::numeric_limits<double>::infinity();
  constexpr std::array<double, 5> kStarts{0.0, -0.5, 0.5, -1.0, 1.0};
  const int per_yaw = std::min<int>(options.bootstrap_starts, static_cast<int>(kStarts.size()));
  const int starts = flow_starts ? 2 * per_yaw : per_yaw;
  struct Start {
    Built built;
    ceres::Solver::Summary summary;
    Extrinsics from;
    bool ok = false;
  };
  std::vector<Start> runs(static_cast<std::size_t>(starts));
  {
    std::vector<std::future<void>> pending;
    for (int i = 0; i < starts; ++i)
      pending.push_back(std::async(std::launch::async, [&, i] {
        const double d = kStarts[static_cast<std::size_t>(i % per_yaw)];
        Extrinsics ex0 = options.prior;
        if (i >= per_yaw) ex0.psi = wrap_angle(flow_yaw - ex0.phi);
        ex0.phi += d;
        ex0.psi -= d;
        Start& r = runs[static_cast<std::size_t>(i)];
        r.from = ex0;
        r.ok = solve_from(ex0, &r.built, &r.summary);
      }));
    for (auto& p : pending) p.get();
  }
  for (Start& r : runs) {
    if (!r.ok) return fail("no track with two bearings in the window");
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
      b = std::move(r.built);
      summary = r.summary;
      have = true;
    }
  }
  if (!have) return fail("window solve failed: " + summary.BriefReport());
  const double gate = std::sqrt(chi2_quantile(options.gate_probability, 1));
  std::map<int, int> origin;  // id given by a split -> the window's id (gap parts: gap_origin)
  // Every renamed id -> the tracker's (for the crossing guard, the parts of one track are one
  // line).
  auto to_tracker = [&] {
    std::map<int, int> m = gap_origin;
    for (const auto& [id, o] : origin) m[id] = gap_origin.count(o) ? gap_origin.at(o) : o;
    return m;
  };
  auto reject_and_solve = [&] {
    if (reject_crossings(&b,
                         options.crossing_guard,
                         options.max_missed_frames,
                         1,
                         to_tracker(),
                         chi2_quantile(options.gate_probability, 2)) > 0) {
      if (b.features.empty()) return;
      ceres::Solve(so, b.problem.get(), &summary);
    }
    if (drop_collapsed_features(&b, options.min_feature_range) > 0) {
      if (b.features.empty()) return;
      ceres::Solve(so, b.problem.get(), &summary);
    }
    for (int round = 0; round < 3; ++round) {
      // One bearing and the inverse-depth prior determine a feature point.
      if (reject_outliers(&b, gate, 1) == 0) break;
      ceres::Solve(so, b.problem.get(), &summary);
    }
  };
  reject_and_solve();
  if (b.features.empty()) return fail("no track left in the window where lines do not cross");
  // Pieces of one line joined as in the refinement (find_merges): where the window is most of
  // the run (the paper trajectory turns 1.5 rad only at frame 87 of 114), the filter's
  // estimate is the window's, and with tracks broken every ~10 frames it was overconfident
  // (NEES 5.6 at the window's end; docs/calib.md, "Broken tracks"). A joined piece takes the
  // id of its line's first piece; the live piece's id continues that feature in the filter
  // (BootstrapDetails::joins).
  CalibrationRun merged_window = window;
  std::vector<std::pair<int, int>> window_merges;  // (first piece's id, joined piece's id)
  for (int round = 0; options.join_pieces && round < kMergeRounds; ++round) {
    BatchPoint at;
    if (!merge_round(&b, options, &merged_window, &at, &window_merges)) break;
    index_tracks(merged_window);
    b = build_window(merged_window, at);
    if (b.features.empty()) return fail("no track with two bearings in the window");
    ceres::Solve(so, b.problem.get(), &summary);
    reject_and_solve();
    if (b.features.empty()) return fail("no track left in the window where lines do not cross");
  }
  // Tracks that slipped onto a neighbouring line are split as in the refinement (find_splits,
  // options.split_chi2): where the window is most of the run (a zigzag never turns 1.5 rad
  // away from its start heading: office zigzag, 252 of 269 frames), the filter's estimate is
  // the window's, and one slipped track biased it (docs/calib.md, "Tracks that slipped onto a
  // neighbouring line").
  // The later part of a split track gets a new id; `origin` maps it to the tracker's.
  CalibrationRun split_window;
  std::vector<std::pair<int, int>> window_splits;
  BatchOptions split_options;
  split_options.split_chi2 = options.split_chi2;
  for (int round = 0; options.split_chi2 > 0.0 && round < split_options.split_rounds; ++round) {
    const std::map<int, int> found = find_splits(b, split_options);
    if (found.empty()) break;
    BatchPoint at = point_of(b);
    split_window = split_round(merged_window,
                               round == 0 ? merged_window : split_window,
                               found,
                               &window_splits,
                               &origin,
                               &at);
    index_tracks(split_window);
    b = build_window(split_window, at);
    if (b.features.empty()) return fail("no track with two bearings in the window");
    ceres::Solve(so, b.problem.get(), &summary);
    reject_and_solve();
    if (b.features.empty()) return fail("no track left in the window where lines do not cross");
  }
  if (options.track_bias_sigma > 0.0) {
    const CalibrationRun& solved = window_splits.empty() ? merged_window : split_window;
    b = add_window_priors(final_with_bias(solved, b, options, window_batch, false, 1));
    if (b.features.empty()) return fail("no track left in the window where lines do not cross");
    ceres::Solve(so, b.problem.get(), &summary);
  }
  const std::map<int, int> renamed = to_tracker();
  auto tracker_id = [&renamed](int id) {
    const auto it = renamed.find(id);
    return it != renamed.end() ? it->second : id;
  };
  // The tracker's id of each bearing of the solved window, (id, frame) -> id: a joined
  // piece's bearings carry its line's first id in the window, their own in the tracker's run
  // (every renaming keeps the order of a frame's bearings).
  std::map<std::pair<int, int>, int> bearing_tracker;
  {
    const CalibrationRun& solved = window_splits.empty() ? merged_window : split_window;
    for (int k = 0; k < W; ++k) {
      const auto& a = solved.frames[static_cast<std::size_t>(k)].observations;
      const auto& o = window_in.frames[static_cast<std::size_t>(k)].observations;
      for (std::size_t i = 0; i < a.size() && i < o.size(); ++i)
        bearing_tracker[{a[i].track_id, k}] = o[i].track_id;
    }
  }
  auto tracker_of_bearing = [&](int id, int k) {
    const auto it = bearing_tracker.find({id, k});
    return it != bearing_tracker.end() ? it->second : tracker_id(id);
  };
  if (!summary.IsSolutionUsable()) return fail("window solve failed: " + summary.BriefReport());
  spdlog::debug("window solved: {} frames, cost {:.6g}, phi {:.4f} rho {:.4f} psi {:.4f}",
                W,
                summary.final_cost,
                b.ex[0],
                b.ex[1],
                b.ex[2]);

  // Covariance of all window variables: inverse of J^T J (priors included).
  ceres::Problem::EvaluateOptions eo;
  std::vector<double*> blocks;
  for (int k = 1; k < W; ++k) blocks.push_back(b.poses[k].data());
  std::map<int, int> feature_col;
  int col = 3 * (W - 1);
  for (auto& [id, f] : b.features) {
    blocks.push_back(f.data());
    feature_col[id] = col;
    col += 2;
  }
  std::map<int, int> bias_col;  // Options::track_bias_sigma
  for (auto& [id, bias] : b.biases) {
    blocks.push_back(&bias);
    bias_col[id] = col++;
  }
  blocks.push_back(b.ex.data());
  const int ex_col = col;
  eo.parameter_blocks = blocks;
  ceres::CRSMatrix crs;
  b.problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd F = information_from_jacobian(crs);
  // A ridge of 1e-10 of each variable's own information: the weights span ten orders of
  // magnitude (a lateral sigma of 1e-5 m against bearings and depth priors), and rounding
  // alone then gave a negative pivot on a regular problem (corridor zigzag seed 29 at
  // --lateral-sigma 1e-5: the window was refused and the filter ended 5 mm off).
  F.diagonal() *= 1.0 + 1e-10;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(F);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0).all())
    return fail("window information is singular");
  const Eigen::MatrixXd Pv = ldlt.solve(Eigen::MatrixXd::Identity(F.rows(), F.cols()));

  // Map to the filter's coordinates at the last window frame: camera pose (c, eta) and, per
  // kept track, (a = c, alpha, q) with alpha, q the direction and inverse distance of the
  // feature from the camera, in the robot frame.
  const int last = W - 1;
  // Per tracker id, its latest part (the line the tracker follows now) enters the state.
  std::map<int, int> latest;  // tracker id -> id in the (split) window
  for (auto& [id, f] : b.features) {
    auto [it, fresh] = latest.emplace(tracker_id(id), id);
    if (!fresh && last_frame[id] > last_frame[it->second]) it->second = id;
  }
  std::vector<int> ids;
  for (const auto& [tid, id] : latest)
    if (last - last_frame[id] <= options.max_missed_frames) ids.push_back(id);
  const int nv = static_cast<int>(F.rows());
  // Each kept track's block: (a_x, a_y, alpha, q), then its bias b when the model has one.
  const bool with_bias = options.track_bias_sigma > 0.0;
  const int fs = with_bias ? 5 : 4;
  const int ns = fs * static_cast<int>(ids.size()) + 3;
  const int pose_col = 3 * (last - 1);  // pose of the last frame (W >= 2)
  auto state_of = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd s(ns);
    const Extrinsics ex{v(ex_col), v(ex_col + 1), v(ex_col + 2)};
    const Vec3 cam = camera_pose_from_extrinsics(ex);
    const Eigen::Vector3d pose = v.segment<3>(pose_col);
    const double c = std::cos(pose(2)), sn = std::sin(pose(2));
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const Vec2 f = v.segment<2>(feature_col[ids[i]]);
      const Vec2 d = f - pose.head<2>();
      const Vec2 fr(c * d(0) + sn * d(1), -sn * d(0) + c * d(1));  // robot frame
      const Vec2 v_c = fr - cam.head<2>();
      s.segment<4>(fs * i) << cam(0), cam(1), std::atan2(v_c(1), v_c(0)), 1.0 / v_c.norm();
      if (with_bias) s(fs * i + 4) = v(bias_col.at(ids[i]));
    }
    s.tail<3>() = cam;
    return s;
  };
  Eigen::VectorXd v0(nv);
  for (int k = 1; k < W; ++k)
    v0.segment<3>(3 * (k - 1)) = Eigen::Map<Eigen::Vector3d>(b.poses[k].data());
  for (auto& [id, f] : b.features)
    v0.segment<2>(feature_col[id]) = Eigen::Map<Eigen::Vector2d>(f.data());
  for (auto& [id, bias] : b.biases) v0(bias_col[id]) = bias;
  v0.segment<3>(ex_col) = Eigen::Map<Eigen::Vector3d>(b.ex.data());
  const Eigen::VectorXd s0 = state_of(v0);
  std::vector<int> cols = {pose_col, pose_col + 1, pose_col + 2, ex_col, ex_col + 1, ex_col + 2};
  for (int id : ids) {
    cols.push_back(feature_col[id]);
    cols.push_back(feature_col[id] + 1);
    if (with_bias) cols.push_back(bias_col.at(id));
  }
  std::vector<int> angle_rows = {ns - 1};
  for (std::size_t i = 0; i < ids.size(); ++i) angle_rows.push_back(fs * static_cast<int>(i) + 2);
  const Eigen::MatrixXd T = central_jacobian(state_of, v0, cols, angle_rows);
  const Eigen::MatrixXd Ps = T * Pv(cols, cols) * T.transpose();
  if (!s0.allFinite() || !Ps.allFinite()) return fail("window solution is not finite");

  if (details) {
    std::map<int, TrackEstimate>* window_tracks = &details->tracks;
    // Every track of the window as the window solved it, (D, theta) from the robot at the
    // track's last window frame (model.hpp, feature_from_world), with its covariance (central
    // differences, as above). Tracks that ended inside the window do not enter the filter's
    // state; without these the refinement would start without them and leave them out
    // (hall zigzag seed 1, a 252-frame window: 130 of 316 tracks refined).
    window_tracks->clear();
    for (const auto& [tid, id] : latest) {
      const int k = last_frame[id];
      const int pc = k > 0 ? 3 * (k - 1) : -1;  // frame 0's pose is the constant origin
      auto d_theta = [&](const Eigen::VectorXd& v) {
        const Eigen::Vector3d pose =
            pc >= 0 ? Eigen::Vector3d(v.segment<3>(pc)) : Eigen::Vector3d::Zero();
        return feature_from_world(pose, v.segment<2>(feature_col[id]));
      };
      std::vector<int> dc = {feature_col[id], feature_col[id] + 1};
      if (pc >= 0) dc.insert(dc.end(), {pc, pc + 1, pc + 2});
      const Eigen::MatrixXd Jt = central_jacobian(d_theta, v0, dc, {1});
      TrackEstimate t;
      t.track_id = tid;
      t.frame = k;
      t.D_theta = d_theta(v0);
      t.covariance = Jt * Pv(dc, dc) * Jt.transpose();
      t.num_updates = count[id];
      if (t.D_theta.allFinite() && t.covariance.allFinite()) (*window_tracks)[tid] = t;
    }
    details->splits.clear();
    for (const auto& [id, k] : window_splits)
      details->splits.emplace_back(gap_origin.count(id) ? gap_origin.at(id) : id, k);
    details->guarded.clear();
    for (const auto& [id, k] : b.guarded)
      details->guarded.emplace_back(tracker_of_bearing(id, k), k);
    {
      // unused_bearings on the solved window's ids, then back to the tracker's.
      const CalibrationRun& solved = window_splits.empty() ? merged_window : split_window;
      details->rejected.clear();
      for (const auto& [id, k] : unused_bearings(solved, b, [](int i) { return i; }))
        details->rejected.emplace_back(tracker_of_bearing(id, k), k);
    }
    // Joined pieces: (the tracker's id of the line's first piece, of the joined piece); each
    // piece's estimate is its line's.
    details->joins.clear();
    for (const auto& [a, c] : window_merges) {
      const int ta = tracker_id(a), tc = tracker_id(c);
      details->joins.emplace_back(ta, tc);
    }
  }

  std::vector<FeatureSlot> slots;
  for (int id : ids) {
    FeatureSlot slot;
    slot.track_id = tracker_id(id);
    slot.param = FeatureParam::kAnchored;
    slot.bias = with_bias;
    slot.first_frame = first_frame[id];
    slot.last_seen_frame = last_frame[id];
    slot.num_updates = count[id];
    slots.push_back(slot);
  }
  FilterState fresh(options.prior, options.prior_sigma, ExtrinsicsParam::kCameraPose);
  fresh.reset(s0, Ps, slots);
  fresh.normalise();
  *state = std::move(fresh);
  return true;
}

}  // namespace omnivert::calib
