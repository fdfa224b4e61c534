// The solved start-up window carried to the filter's state (bootstrap_filter_state).

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "calib/window.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"

namespace omnivert::calib::internal {

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

// The window's variables in the order of its Jacobian's columns: poses of frames 1..W-1
// (frame 0 is the gauge), features (2 columns each), track biases
// (CalibrationOptions::noise.track_bias_sigma), extrinsics (3).
struct WindowColumns {
  std::vector<double*> blocks;
  std::map<int, int> feature;  // track id -> first column
  std::map<int, int> bias;     // track id -> column
  int ex = 0;
};

WindowColumns window_columns(Built& b, int W) {
  WindowColumns c;
  for (int k = 1; k < W; ++k) c.blocks.push_back(b.poses[k].data());
  int col = 3 * (W - 1);
  for (auto& [id, f] : b.features) {
    c.blocks.push_back(f.data());
    c.feature[id] = col;
    col += 2;
  }
  for (auto& [id, bias] : b.biases) {
    c.blocks.push_back(&bias);
    c.bias[id] = col++;
  }
  c.blocks.push_back(b.ex.data());
  c.ex = col;
  return c;
}

// Covariance of all window variables: inverse of J^T J (priors included). false when the
// information is singular.
bool window_covariance(Built& b, const WindowColumns& c, Eigen::MatrixXd* Pv) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = c.blocks;
  ceres::CRSMatrix crs;
  b.problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd F = information_from_jacobian(crs);
  // A ridge of 1e-10 of each variable's own information: the weights span ten orders of
  // magnitude (a lateral sigma of 1e-5 m against bearings and depth priors), and rounding
  // alone can give a negative pivot on a regular problem.
  F.diagonal() *= 1.0 + 1e-10;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(F);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0).all()) return false;
  *Pv = ldlt.solve(Eigen::MatrixXd::Identity(F.rows(), F.cols()));
  return true;
}

// The window's solution as a vector in the columns' order.
Eigen::VectorXd window_values(Built& b, const WindowColumns& c, int W, int nv) {
  Eigen::VectorXd v0(nv);
  for (int k = 1; k < W; ++k)
    v0.segment<3>(3 * (k - 1)) = Eigen::Map<Eigen::Vector3d>(b.poses[k].data());
  for (auto& [id, f] : b.features)
    v0.segment<2>(c.feature.at(id)) = Eigen::Map<Eigen::Vector2d>(f.data());
  for (auto& [id, bias] : b.biases) v0(c.bias.at(id)) = bias;
  v0.segment<3>(c.ex) = Eigen::Map<Eigen::Vector3d>(b.ex.data());
  return v0;
}

// Per tracker id, its latest part (the line the tracker follows now): tracker id -> id in the
// (split) window.
std::map<int, int> latest_parts(const Built& b, const WindowIds& ids, const WindowTracks& t) {
  std::map<int, int> latest;
  for (const auto& [id, f] : b.features) {
    auto [it, fresh] = latest.emplace(ids.tracker_id(id), id);
    if (!fresh && t.last(id) > t.last(it->second)) it->second = id;
  }
  return latest;
}

// The window's solution and covariance (v0, Pv) in the filter's coordinates at the last
// window frame: per kept track (ids) (a_x, a_y, alpha, q), the camera position as the anchor
// and alpha, q the direction and inverse distance of the feature from the camera in the robot
// frame, then its bias b when the model has one; the camera pose (c, eta) last. Carried
// through central differences. false when not finite.
bool filter_coordinates(const Eigen::VectorXd& v0,
                        const Eigen::MatrixXd& Pv,
                        const WindowColumns& c,
                        const std::vector<int>& ids,
                        bool with_bias,
                        int W,
                        Eigen::VectorXd* s0,
                        Eigen::MatrixXd* Ps) {
  const int last = W - 1;
  const int fs = with_bias ? 5 : 4;  // a kept track's block
  const int ns = fs * static_cast<int>(ids.size()) + 3;
  const int pose_col = 3 * (last - 1);  // pose of the last frame (W >= 2)
  auto state_of = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd s(ns);
    const Extrinsics ex{v(c.ex), v(c.ex + 1), v(c.ex + 2)};
    const Vec3 cam = camera_pose_from_extrinsics(ex);
    const Eigen::Vector3d pose = v.segment<3>(pose_col);
    const double cs = std::cos(pose(2)), sn = std::sin(pose(2));
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const Vec2 f = v.segment<2>(c.feature.at(ids[i]));
      const Vec2 d = f - pose.head<2>();
      const Vec2 fr(cs * d(0) + sn * d(1), -sn * d(0) + cs * d(1));  // robot frame
      const Vec2 v_c = fr - cam.head<2>();
      s.segment<4>(fs * i) << cam(0), cam(1), std::atan2(v_c(1), v_c(0)), 1.0 / v_c.norm();
      if (with_bias) s(fs * i + 4) = v(c.bias.at(ids[i]));
    }
    s.tail<3>() = cam;
    return s;
  };
  *s0 = state_of(v0);
  std::vector<int> cols = {pose_col, pose_col + 1, pose_col + 2, c.ex, c.ex + 1, c.ex + 2};
  for (int id : ids) {
    cols.push_back(c.feature.at(id));
    cols.push_back(c.feature.at(id) + 1);
    if (with_bias) cols.push_back(c.bias.at(id));
  }
  std::vector<int> angle_rows = {ns - 1};
  for (std::size_t i = 0; i < ids.size(); ++i) angle_rows.push_back(fs * static_cast<int>(i) + 2);
  const Eigen::MatrixXd T = central_jacobian(state_of, v0, cols, angle_rows);
  // Evaluated into a new matrix, then moved: assigned to *Ps directly, Eigen takes another
  // evaluation path, which rounds differently.
  Eigen::MatrixXd P = T * Pv(cols, cols) * T.transpose();
  *Ps = std::move(P);
  return s0->allFinite() && Ps->allFinite();
}

// Every track of the window as the window solved it, (D, theta) from the robot at the track's
// last window frame (model.hpp, feature_from_world), with its covariance (central
// differences). Tracks that ended inside the window do not enter the filter's state; without
// these the refinement would start without them and leave them out.
std::map<int, TrackEstimate> window_tracks(const std::map<int, int>& latest,
                                           const WindowTracks& tracks,
                                           const WindowColumns& c,
                                           const Eigen::VectorXd& v0,
                                           const Eigen::MatrixXd& Pv) {
  std::map<int, TrackEstimate> out;
  for (const auto& [tid, id] : latest) {
    const int k = tracks.last(id);
    const int pc = k > 0 ? 3 * (k - 1) : -1;  // frame 0's pose is the constant origin
    const int fc = c.feature.at(id);
    auto d_theta = [&](const Eigen::VectorXd& v) {
      const Eigen::Vector3d pose =
          pc >= 0 ? Eigen::Vector3d(v.segment<3>(pc)) : Eigen::Vector3d::Zero();
      return feature_from_world(pose, v.segment<2>(fc));
    };
    std::vector<int> dc = {fc, fc + 1};
    if (pc >= 0) dc.insert(dc.end(), {pc, pc + 1, pc + 2});
    const Eigen::MatrixXd Jt = central_jacobian(d_theta, v0, dc, {1});
    TrackEstimate t;
    t.track_id = tid;
    t.frame = k;
    t.D_theta = d_theta(v0);
    t.covariance = Jt * Pv(dc, dc) * Jt.transpose();
    t.num_updates = tracks.bearings(id);
    if (t.D_theta.allFinite() && t.covariance.allFinite()) out[tid] = t;
  }
  return out;
}

// What the window decided, by the tracker's ids (BootstrapDetails).
void window_decisions(const Built& b,
                      const WindowIds& ids,
                      const Association& association,
                      const std::map<int, int>& gap_origin,
                      BootstrapDetails* details) {
  details->splits.clear();
  for (const auto& [id, k] : association.splits)
    details->splits.emplace_back(gap_origin.count(id) ? gap_origin.at(id) : id, k);
  details->guarded.clear();
  for (const auto& [id, k] : b.guarded) details->guarded.emplace_back(ids.of_bearing(id, k), k);
  // unused_bearings on the solved window's ids, then back to the tracker's.
  details->rejected.clear();
  for (const auto& [id, k] : unused_bearings(association.solved(), b, [](int i) { return i; }))
    details->rejected.emplace_back(ids.of_bearing(id, k), k);
  // Joined pieces: (the tracker's id of the line's first piece, of the joined piece); each
  // piece's estimate is its line's.
  details->joins.clear();
  for (const auto& [a, c] : association.merges)
    details->joins.emplace_back(ids.tracker_id(a), ids.tracker_id(c));
}

// The filter's state from the window: the kept tracks as anchored features.
FilterState filter_state(const CalibrationOptions& options,
                         const std::vector<int>& ids,
                         const WindowIds& names,
                         const WindowTracks& tracks,
                         const Eigen::VectorXd& s0,
                         const Eigen::MatrixXd& Ps) {
  std::vector<FeatureSlot> slots;
  for (int id : ids) {
    FeatureSlot slot;
    slot.track_id = names.tracker_id(id);
    slot.param = FeatureParam::kAnchored;
    slot.bias = options.noise.track_bias_sigma > 0.0;
    slot.first_frame = tracks.first(id);
    slot.last_seen_frame = tracks.last(id);
    slot.num_updates = tracks.bearings(id);
    slots.push_back(slot);
  }
  FilterState fresh(options.prior.mean, options.prior.sigma, ExtrinsicsParam::kCameraPose);
  fresh.reset(s0, Ps, slots);
  fresh.normalise();
  return fresh;
}

}  // namespace

bool window_to_filter(Built& b,
                      const CalibrationOptions& options,
                      int W,
                      const WindowTracks& tracks,
                      const WindowIds& ids,
                      const Association& association,
                      const std::map<int, int>& gap_origin,
                      FilterState* state,
                      BootstrapDetails* details,
                      std::string* why) {
  const WindowColumns c = window_columns(b, W);
  Eigen::MatrixXd Pv;
  if (!window_covariance(b, c, &Pv)) {
    *why = "window information is singular";
    return false;
  }
  // The tracks that enter the state: the latest part of each tracker id, seen within
  // max_missed_frames of the window's last frame.
  const std::map<int, int> latest = latest_parts(b, ids, tracks);
  std::vector<int> kept;
  for (const auto& [tid, id] : latest)
    if (W - 1 - tracks.last(id) <= options.association.max_missed_frames) kept.push_back(id);
  const Eigen::VectorXd v0 = window_values(b, c, W, static_cast<int>(Pv.rows()));
  Eigen::VectorXd s0;
  Eigen::MatrixXd Ps;
  if (!filter_coordinates(v0, Pv, c, kept, options.noise.track_bias_sigma > 0.0, W, &s0, &Ps)) {
    *why = "window solution is not finite";
    return false;
  }
  if (details) {
    details->tracks = window_tracks(latest, tracks, c, v0, Pv);
    window_decisions(b, ids, association, gap_origin, details);
  }
  *state = filter_state(options, kept, ids, tracks, s0, Ps);
  return true;
}

}  // namespace omnivert::calib::internal
