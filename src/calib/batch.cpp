#include "omnivert/calib/batch.hpp"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <array>
#include <set>
#include <limits>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>

#include "omnivert/calib/model.hpp"
#include "omnivert/calib/updater.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

namespace {

// Odometry factor between poses i and j = i + 1: eq. (14)-(15) inverted. The pose change
// gives d_theta and, along the mid-step heading, d_rho; the motion across it must be the
// wheels' (FrameInput::lateral, 0 for one step of eq. 14).
// The three residuals are whitened by W (W^T W = the inverse covariance of the wheels' step,
// FrameInput::covariance_per_K, or diagonal for one step).
struct OdometryResidual {
  double d_right, d_left, lateral_measured, e;
  Eigen::Matrix3d W;
  template <typename T>
  bool operator()(const T* pi, const T* pj, T* r) const {
    const T dth = pj[2] - pi[2];
    const T mid = pi[2] + 0.5 * dth;
    const T dx = pj[0] - pi[0], dy = pj[1] - pi[1];
    const T c = cos(mid), s = sin(mid);
    const T d_rho = c * dx + s * dy;
    const T lateral = -s * dx + c * dy;
    const T dR = d_rho + 0.5 * e * dth;  // eq. (15) solved for the wheels
    const T dL = d_rho - 0.5 * e * dth;
    const T v[3] = {dR - d_right, dL - d_left, lateral - lateral_measured};
    for (int i = 0; i < 3; ++i) r[i] = W(i, 0) * v[0] + W(i, 1) * v[1] + W(i, 2) * v[2];
    return true;
  }
};

// Bearing factor: beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi), residual wrapped
// to (-pi, pi] and whitened; `offset` is added to the prediction (a track's constant error).
template <typename T>
T bearing_residual(double beta, double inv_sigma, const T* pose, const T* f, const T* ex,
                   const T& offset) {
  const T a = pose[2] + ex[0];
  const T xc = pose[0] + ex[1] * cos(a);
  const T yc = pose[1] + ex[1] * sin(a);
  const T pred = atan2(f[1] - yc, f[0] - xc) - (pose[2] + ex[0] + ex[2]) + offset;
  const T d = T(beta) - pred;
  return atan2(sin(d), cos(d)) * inv_sigma;
}
struct BearingResidual {
  double beta, inv_sigma;
  template <typename T>
  bool operator()(const T* pose, const T* f, const T* ex, T* r) const {
    r[0] = bearing_residual(beta, inv_sigma, pose, f, ex, T(0.0));
    return true;
  }
};
// Options::track_bias_sigma: the bearing with the track's constant error b added to
// eq. (30)'s prediction, and b's prior.
struct BiasedBearingResidual {
  double beta, inv_sigma;
  template <typename T>
  bool operator()(const T* pose, const T* f, const T* ex, const T* bias, T* r) const {
    r[0] = bearing_residual(beta, inv_sigma, pose, f, ex, bias[0]);
    return true;
  }
};
struct BiasPrior {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* bias, T* r) const {
    r[0] = bias[0] * inv_sigma;
    return true;
  }
};

// The problem with its parameter storage.
struct Built {
  std::vector<std::array<double, 3>> poses;
  std::map<int, std::array<double, 2>> features;
  std::map<int, double> biases;  // Options::track_bias_sigma (std::map: stable addresses)
  std::map<int, ceres::ResidualBlockId> bias_priors;  // their priors, by track
  std::vector<double> ex = std::vector<double>(3, 0.0);  // heap storage: Built moves keep the address Ceres holds
  std::unique_ptr<ceres::Problem> problem;
  int num_bearings = 0;
  std::vector<ceres::ResidualBlockId> bearing_blocks;
  std::vector<std::pair<int, int>> bearing_keys;  // (track id, frame) of each bearing block
  std::vector<ceres::ResidualBlockId> odometry_blocks;
  std::vector<std::pair<int, int>> guarded;  // (track id, frame) left out by reject_crossings
};

// Keeps the bearings for which keep(block, (track id, frame)) is true; the others leave the
// problem's bookkeeping (the caller removes their residual blocks, or their parameter block).
// Returns how many left.
template <typename Keep>
int filter_bearings(Built* b, Keep keep) {
  std::vector<ceres::ResidualBlockId> kept;
  std::vector<std::pair<int, int>> kept_keys;
  for (std::size_t i = 0; i < b->bearing_blocks.size(); ++i) {
    if (!keep(b->bearing_blocks[i], b->bearing_keys[i])) continue;
    kept.push_back(b->bearing_blocks[i]);
    kept_keys.push_back(b->bearing_keys[i]);
  }
  const int n = static_cast<int>(b->bearing_blocks.size() - kept.size());
  b->num_bearings -= n;
  b->bearing_blocks = std::move(kept);
  b->bearing_keys = std::move(kept_keys);
  return n;
}

// Removes the given features with their bearings and any prior on them. Returns how many.
int remove_features(Built* b, const std::set<int>& drop) {
  if (drop.empty()) return 0;
  filter_bearings(b, [&](ceres::ResidualBlockId, const std::pair<int, int>& key) {
    return !drop.count(key.first);
  });
  for (int id : drop) {
    if (auto it = b->biases.find(id); it != b->biases.end()) {
      b->problem->RemoveParameterBlock(&it->second);  // and its prior
      b->biases.erase(it);
      b->bias_priors.erase(id);
    }
    b->problem->RemoveParameterBlock(b->features.at(id).data());  // and its residual blocks
    b->features.erase(id);
  }
  return static_cast<int>(drop.size());
}

// The bearings of `run` that the solved problem `b` neither uses nor guarded (outliers, and
// those of features removed), as (track id of `run`, frame); `to_run` maps the problem's
// track ids to `run`'s (renamed parts of a track).
template <typename ToRun>
std::vector<std::pair<int, int>> unused_bearings(const CalibrationRun& run,
                                                 const Built& b,
                                                 ToRun to_run) {
  std::set<std::pair<int, int>> out;
  for (std::size_t k = 0; k < run.frames.size(); ++k)
    for (const BearingObservation& o : run.frames[k].observations)
      out.emplace(o.track_id, static_cast<int>(k));
  for (const auto& [id, k] : b.bearing_keys) out.erase({to_run(id), k});
  for (const auto& [id, k] : b.guarded) out.erase({to_run(id), k});
  return {out.begin(), out.end()};
}

// Removes the features left with fewer than `min_bearings` bearings (with their remaining
// bearings and any prior on them): their information is singular. Measured: hall zigzag,
// seed 1, every bearing of one track was an outlier in the filter's bootstrap window, whose
// information matrix then could not be inverted; the filter fell back on the undelayed
// initialisation over 252 frames and ended 124 mm off (docs/calib.md, "The noise check").
// Returns how many features.
int drop_unobserved_features(Built* b, int min_bearings) {
  std::map<int, int> count;
  for (const auto& [id, frame] : b->bearing_keys) ++count[id];
  std::set<int> drop;
  for (const auto& [id, f] : b->features)
    if (count[id] < min_bearings) drop.insert(id);
  return remove_features(b, drop);
}

// Removes the features that the solution puts closer than `min_range` to the camera centre
// (eq. 16-17) at a frame with one of their bearings (Options::min_feature_range), with their
// bearings and any prior on them. Returns how many features.
int drop_collapsed_features(Built* b, double min_range) {
  std::set<int> drop;
  for (const auto& [id, k] : b->bearing_keys) {
    const auto& p = b->poses[static_cast<std::size_t>(k)];
    const auto& f = b->features.at(id);
    const double a = p[2] + b->ex[0];
    const double range =
        std::hypot(f[0] - p[0] - b->ex[1] * std::cos(a), f[1] - p[1] - b->ex[1] * std::sin(a));
    if (!(range >= min_range)) drop.insert(id);
  }
  return remove_features(b, drop);
}

// Removes the bearings whose whitened residual exceeds `threshold` (the filter's chi-square
// gate, in sigmas) at the current solution, then the features left with fewer than
// `min_bearings` bearings (drop_unobserved_features). Returns how many bearings.
int reject_outliers(Built* b, double threshold, int min_bearings) {
  const int n = filter_bearings(b, [&](ceres::ResidualBlockId id, const std::pair<int, int>&) {
    double r = 0.0, cost = 0.0;
    b->problem->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, &r, nullptr);
    if (std::abs(r) <= threshold) return true;  // (false for NaN)
    b->problem->RemoveResidualBlock(id);
    return false;
  });
  if (n > 0) drop_unobserved_features(b, min_bearings);
  return n;
}

Eigen::SparseMatrix<double> sparse_jacobian(const ceres::CRSMatrix& crs);
std::vector<double*> variable_blocks(Built& b);

// F = J^T J with a tiny ridge, relative to each variable's own information (their scales
// differ by orders of magnitude): it keeps a feature seen without parallax from making F
// singular. A variable without any residual left (a feature whose bearings were all removed
// as outliers: hall zigzag, seed 1) has an empty row and column; a unit diagonal leaves it
// out of everything else.
Eigen::SparseMatrix<double> information_with_ridge(const Eigen::SparseMatrix<double>& J) {
  Eigen::SparseMatrix<double> F = J.transpose() * J;
  for (int i = 0; i < F.rows(); ++i) {
    double& d = F.coeffRef(i, i);
    d = d > 0.0 ? d * (1.0 + 1e-10) : 1.0;
  }
  return F;
}

// The frames of each track's bearings in the problem, in order.
std::map<int, std::vector<int>> track_frames(const Built& b) {
  std::map<int, std::vector<int>> out;
  for (const auto& [id, k] : b.bearing_keys) out[id].push_back(k);
  for (auto& [id, v] : out) std::sort(v.begin(), v.end());
  return out;
}

// Whether two sorted frame lists have a frame in common.
bool share_a_frame(const std::vector<int>& a, const std::vector<int>& c) {
  for (std::size_t i = 0, j = 0; i < a.size() && j < c.size();) {
    if (a[i] == c[j]) return true;
    a[i] < c[j] ? ++i : ++j;
  }
  return false;
}

// Whether tracks a and c are one line: the Wald statistic of "one feature point" (f_a = f_c)
// at the current solution, d^T Cov(d)^-1 d with d = f_a - f_c and Cov(d) from the inverse of
// the whole problem's information (poses and extrinsics free: held fixed, the poses' own
// uncertainty made pieces of one line look apart, statistics up to 370 at 0.025 degree), is
// below `chi2` (chi-square, 2 degrees of freedom). The factorisation is made once per call
// of reject_crossings (`cache`), the columns of each feature once.
struct FeatureCovariance {
  bool ready = false, ok = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  std::map<int, int> column;              // track id -> first column
  std::map<int, Eigen::MatrixXd> solved;  // track id -> F^-1 (:, its two columns)
};
// The statistic itself (infinity when it cannot be computed).
double one_line_statistic(Built* b, int a, int c, FeatureCovariance* cache) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (!cache->ready) {
    cache->ready = true;
    ceres::Problem::EvaluateOptions eo;
    eo.parameter_blocks = variable_blocks(*b);
    eo.apply_loss_function = false;
    ceres::CRSMatrix crs;
    if (!b->problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs)) return kNone;
    cache->ldlt.compute(information_with_ridge(sparse_jacobian(crs)));
    cache->ok = cache->ldlt.info() == Eigen::Success && (cache->ldlt.vectorD().array() > 0).all();
    int col = 3 * (static_cast<int>(b->poses.size()) - 1);
    for (const auto& [id, f] : b->features) {
      cache->column[id] = col;
      col += 2;
    }
  }
  if (!cache->ok) return kNone;
  auto columns = [cache](int id) -> const Eigen::MatrixXd& {
    auto it = cache->solved.find(id);
    if (it != cache->solved.end()) return it->second;
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(cache->ldlt.rows(), 2);
    E(cache->column.at(id), 0) = E(cache->column.at(id) + 1, 1) = 1.0;
    return cache->solved[id] = cache->ldlt.solve(E);
  };
  const Eigen::MatrixXd& Xa = columns(a);
  const Eigen::MatrixXd& Xc = columns(c);
  const int ia = cache->column.at(a), ic = cache->column.at(c);
  const Eigen::Matrix2d C = Xa.middleRows<2>(ia) + Xc.middleRows<2>(ic) - Xa.middleRows<2>(ic) -
                            Xc.middleRows<2>(ia);
  const std::array<double, 2>& fa = b->features.at(a);
  const std::array<double, 2>& fc = b->features.at(c);
  const Eigen::Vector2d d(fa[0] - fc[0], fa[1] - fc[1]);
  const Eigen::LDLT<Eigen::Matrix2d> cl(0.5 * (C + C.transpose()));
  if (cl.info() != Eigen::Success || !(cl.vectorD().array() > 0).all()) return kNone;
  const double t = d.dot(cl.solve(d));
  return std::isfinite(t) ? t : kNone;
}
bool one_line(Built* b, int a, int c, double chi2, FeatureCovariance* cache) {
  return one_line_statistic(b, a, c, cache) < chi2;
}

// The crossing guard (Options::crossing_guard): removes the bearings of a feature at the
// frames where another feature, over its track's span (first to last bearing) widened by
// `margin` frames on each side, is predicted within `guard` of it as seen from the camera,
// at the current solution. (The widening: a track often starts or ends where its line met
// another, its detections given to the other track meanwhile; the tracker bridges gaps of
// max_missed_frames, the margin used.) There the extractor
// sees one line where there are two: the detection is pulled towards the other line, or
// belongs to it (office paper, seed 9: track 3 pulled by up to 0.19 degree by lines passing
// within 1 degree, and then split by the slip test although it never left its line;
// docs/calib.md, "Lines that cross"). The bearings are not independent Gaussian errors about
// the line there, which is what eq. (30) assumes. Then the features left with fewer than
// `min_bearings` bearings go (drop_unobserved_features). Returns how many bearings; their
// keys are added to b->guarded.
// A line the tracker lost and found again under a new id is not a crossing either: two tracks
// that never share a frame and whose bearings one point explains (one_line) are one line.
// Without this a track's pieces guarded each other over the margin, and with tracks broken
// every ~10 frames the guard left out most bearings (synthetic paper run, break probability
// 0.1: 950 of 1140 in the filter, most features of the refinement).
int reject_crossings(Built* b,
                     double guard,
                     int margin,
                     int min_bearings,
                     const std::map<int, int>& origin,
                     double merge_chi2) {
  if (!(guard > 0.0) || b->features.empty()) return 0;
  std::map<int, std::pair<int, int>> span;  // track id -> (first, last) frame
  for (const auto& [id, k] : b->bearing_keys) {
    auto [it, fresh] = span.emplace(id, std::make_pair(k, k));
    it->second.first = std::min(it->second.first, k);
    it->second.second = std::max(it->second.second, k);
  }
  // Per frame, the direction of each live feature from the camera centre (eq. 16-17).
  const int frames = static_cast<int>(b->poses.size());
  std::vector<std::vector<std::pair<double, int>>> seen(static_cast<std::size_t>(frames));
  for (const auto& [id, f] : b->features) {
    const auto it = span.find(id);
    if (it == span.end()) continue;
    const int from = std::max(it->second.first - margin, 0);
    const int to = std::min(it->second.second + margin, frames - 1);
    for (int k = from; k <= to; ++k) {
      const auto& p = b->poses[static_cast<std::size_t>(k)];
      const double xc = p[0] + b->ex[1] * std::cos(p[2] + b->ex[0]);
      const double yc = p[1] + b->ex[1] * std::sin(p[2] + b->ex[0]);
      seen[static_cast<std::size_t>(k)].emplace_back(std::atan2(f[1] - yc, f[0] - xc), id);
    }
  }
  // Two parts of one split track are one line, not a crossing.
  auto tracker = [&origin](int id) {
    const auto it = origin.find(id);
    return it != origin.end() ? it->second : id;
  };
  std::map<std::pair<int, int>, bool> merged;  // (a, c), a < c -> one_line's verdict
  FeatureCovariance covariance;
  const std::map<int, std::vector<int>> frames_of = track_frames(*b);
  const auto same_line = [&](int a, int c) {
    if (tracker(a) == tracker(c)) return true;
    if (!(merge_chi2 > 0.0) || share_a_frame(frames_of.at(a), frames_of.at(c))) return false;
    const auto key = std::minmax(a, c);
    const auto it = merged.find(key);
    if (it != merged.end()) return it->second;
    return merged[key] = one_line(b, a, c, merge_chi2, &covariance);
  };
  std::set<std::pair<int, int>> crossing;  // (track id, frame)
  for (int k = 0; k < frames; ++k)
    for (int id : crowded_directions(std::move(seen[static_cast<std::size_t>(k)]), guard, same_line))
      crossing.emplace(id, k);
  if (crossing.empty()) return 0;
  const int n = filter_bearings(b, [&](ceres::ResidualBlockId id, const std::pair<int, int>& key) {
    if (!crossing.count(key)) return true;
    b->problem->RemoveResidualBlock(id);
    b->guarded.push_back(key);
    return false;
  });
  if (n > 0) drop_unobserved_features(b, min_bearings);
  return n;
}

// The likelihood-ratio statistic of "one point" for tracks a and c with the poses and the
// extrinsics held at the current solution: the least squares cost of all their bearings
// about the one point that fits them best (Gauss-Newton from each of the two points) minus
// their costs about their own points (the solution's, optimal there). About chi-square(2)
// under one point. Unlike the Wald test it keeps its power when a piece is too short to
// place its point: three bearings over three frames have no depth, their point's covariance
// is enormous along the ray, and the Wald statistic of a piece of another line came out
// 0.00 (synthetic, seed 90, tracks broken every ~10 frames: 4 of 44 joins wrong).
double one_point_statistic(Built* b, const std::vector<std::size_t>& blocks, int a, int c) {
  auto cost = [&](double* jtj, double* jtr) {
    double s = 0.0;
    for (std::size_t i : blocks) {
      double r = 0.0, j[2] = {0.0, 0.0};
      double* jac[4] = {nullptr, j, nullptr, nullptr};  // (pose, feature, extrinsics[, track bias])
      if (!b->problem->EvaluateResidualBlock(b->bearing_blocks[i], false, nullptr, &r,
                                             jtj ? jac : nullptr))
        return std::numeric_limits<double>::infinity();
      s += r * r;
      if (jtj) {
        jtj[0] += j[0] * j[0], jtj[1] += j[0] * j[1], jtj[2] += j[1] * j[1];
        jtr[0] += j[0] * r, jtr[1] += j[1] * r;
      }
    }
    return s;
  };
  std::array<double, 2>& fa = b->features.at(a);
  std::array<double, 2>& fc = b->features.at(c);
  const std::array<double, 2> own_a = fa, own_c = fc;
  const double separate = cost(nullptr, nullptr);
  double best = std::numeric_limits<double>::infinity();
  for (const std::array<double, 2>& start : {own_a, own_c}) {
    fa = fc = start;
    for (int it = 0; it < 10; ++it) {
      double h[3] = {0, 0, 0}, g[2] = {0, 0};
      const double now = cost(h, g);
      if (!std::isfinite(now)) break;
      best = std::min(best, now);
      const double det = h[0] * h[2] - h[1] * h[1];
      if (!(det > 0.0)) break;
      const double dx = -(h[2] * g[0] - h[1] * g[1]) / det;
      const double dy = -(h[0] * g[1] - h[1] * g[0]) / det;
      fa[0] += dx, fa[1] += dy;
      fc = fa;
      if (std::hypot(dx, dy) < 1e-9) break;
    }
    best = std::min(best, cost(nullptr, nullptr));
  }
  fa = own_a;
  fc = own_c;
  return best - separate;
}

// Pieces of one line (BatchOptions::merge_pieces, Options::join_pieces): a tracker that loses
// a line and finds it again gives it a new id, and the batch then has two features where
// there is one point. Each piece is estimated from its own few bearings, from little
// parallax; with tracks broken every ~10 frames (synthetic paper runs, calib_monte_carlo
// --break 0.1) the refinement's NEES was 4.1 over 100 runs where the unbroken tracks give 2.9
// (docs/calib.md, "Broken tracks"). Candidates: two tracks that never share a frame, at most
// `max_gap` frames apart (or interleaved: a chain of joins can skip a piece, which a later
// round then joins). They are one line when one point explains both, by two tests that must
// agree: one_point_statistic (poses held; keeps its power for a piece without depth) and the
// Wald statistic of one_line (the whole problem's covariance; poses free, so long pieces of
// one line are not held apart by pose errors: 7% of them failed the first test alone at
// chi-square(2), 0.999), each below `chi2`. Each track joins at most one successor and one
// predecessor per round, the pairs with the smallest first statistic first (each track in at
// most one join per round: 100 synthetic runs broken every ~10 frames, refinement NEES 4.25
// against 3.17). Returns (a, c) pairs, a the piece seen first: c's bearings are a's line.
std::vector<std::pair<int, int>> find_merges(Built* b, int max_gap, double chi2) {
  const std::map<int, std::vector<int>> frames_of = track_frames(*b);
  std::map<int, std::vector<std::size_t>> blocks;  // track id -> its bearings' blocks
  for (std::size_t i = 0; i < b->bearing_keys.size(); ++i) blocks[b->bearing_keys[i].first].push_back(i);
  FeatureCovariance covariance;
  std::vector<std::tuple<double, int, int>> passing;  // (statistic, a, c)
  for (auto ia = frames_of.begin(); ia != frames_of.end(); ++ia)
    for (auto ic = std::next(ia); ic != frames_of.end(); ++ic) {
      const std::vector<int>& fa = ia->second;
      const std::vector<int>& fc = ic->second;
      const int gap = std::max(fc.front() - fa.back(), fa.front() - fc.back());
      if (gap > max_gap || share_a_frame(fa, fc)) continue;
      // a: the piece seen first.
      const int a = fa.front() <= fc.front() ? ia->first : ic->first;
      const int c = a == ia->first ? ic->first : ia->first;
      // The Wald test first: after one factorisation per call it costs two small solves per
      // track, where the likelihood ratio re-fits a point to both tracks' bearings.
      if (!(one_line_statistic(b, a, c, &covariance) < chi2)) continue;
      std::vector<std::size_t> both = blocks.at(a);
      both.insert(both.end(), blocks.at(c).begin(), blocks.at(c).end());
      const double lr = one_point_statistic(b, both, a, c);
      if (lr < chi2) passing.emplace_back(lr, a, c);
    }
  std::sort(passing.begin(), passing.end());
  std::set<int> has_successor, has_predecessor;
  std::vector<std::pair<int, int>> out;
  for (const auto& [t, a, c] : passing) {
    if (has_successor.count(a) || has_predecessor.count(c)) continue;
    has_successor.insert(a);
    has_predecessor.insert(c);
    out.emplace_back(a, c);
  }
  return out;
}


// Track splitting (BatchOptions::split_chi2). A track that slipped onto a neighbouring line
// (a door leaf 6 cm inside its frame) is two features glued together: from the frame of the
// slip on, its bearings follow another point. For each track and each split frame j, the
// likelihood-ratio statistic of "two features, before and after j" against "one feature"
// with poses and extrinsics held at the current solution, linearised there: with the whitened
// residuals r_i and their Jacobians J_i (1x2) on the feature point, each segment's best
// feature step reduces the squared residuals by g^T H^-1 g (g = sum J_i^T r_i,
// H = sum J_i^T J_i), computed for every j at once from prefix sums. Under no slip the
// statistic at a fixed j is chi-square with 2 degrees of freedom. Returns track id -> first
// frame of the second segment for tracks whose best statistic exceeds the threshold.
std::map<int, int> find_splits(const Built& b, const BatchOptions& batch) {
  struct Row {
    int frame;
    double r;
    Eigen::Vector2d J;
  };
  std::map<int, std::vector<Row>> seq;
  // Only the feature's Jacobian: Ceres refuses (and logs) a Jacobian of a constant block, and
  // frame 0's pose is constant (the gauge).
  double jf[2];
  double* jac[4] = {nullptr, jf, nullptr, nullptr};  // (pose, feature, extrinsics[, track bias])
  for (std::size_t i = 0; i < b.bearing_blocks.size(); ++i) {  // bearing_keys is parallel
    double r = 0.0, cost = 0.0;
    if (!b.problem->EvaluateResidualBlock(b.bearing_blocks[i], /*apply_loss_function=*/false,
                                          &cost, &r, jac) ||
        !std::isfinite(r) || !std::isfinite(jf[0]) || !std::isfinite(jf[1]))
      continue;
    seq[b.bearing_keys[i].first].push_back({b.bearing_keys[i].second, r, Eigen::Vector2d(jf[0], jf[1])});
  }
  std::vector<std::tuple<double, int, int>> candidates;  // (statistic, track id, split frame)
  const int m = std::max(batch.split_min_bearings, 2);
  auto gain = [](const Eigen::Matrix2d& H, const Eigen::Vector2d& g) {
    const Eigen::Matrix2d Hr = H + 1e-9 * (H.trace() + 1e-12) * Eigen::Matrix2d::Identity();
    return g.dot(Hr.ldlt().solve(g));
  };
  for (auto& [id, v] : seq) {
    const int n = static_cast<int>(v.size());
    if (n < 2 * m) continue;
    std::sort(v.begin(), v.end(), [](const Row& x, const Row& y) { return x.frame < y.frame; });
    std::vector<Eigen::Matrix2d> H(n + 1, Eigen::Matrix2d::Zero());
    std::vector<Eigen::Vector2d> g(n + 1, Eigen::Vector2d::Zero());
    for (int i = 0; i < n; ++i) {
      H[i + 1] = H[i] + v[i].J * v[i].J.transpose();
      g[i + 1] = g[i] + v[i].J * v[i].r;
    }
    const double whole = gain(H[n], g[n]);  // ~0 at a solution; kept for exactness
    double best = 0.0;
    int best_j = -1;
    for (int j = m; j <= n - m; ++j) {
      const double t = gain(H[j], g[j]) + gain(H[n] - H[j], g[n] - g[j]) - whole;
      if (t > best) {
        best = t;
        best_j = j;
      }
    }
    if (best_j > 0 && best > batch.split_chi2) candidates.push_back({best, id, v[best_j].frame});
  }
  // A slip biases the extrinsics, and a biased solution leaves structure in the residuals of
  // clean tracks too: only the tracks within a factor split_keep_fraction of the strongest
  // statistic are split in this round; the others are judged again after the re-solve.
  std::sort(candidates.begin(), candidates.end(), std::greater<>());
  std::map<int, int> out;
  for (const auto& [t, id, frame] : candidates)
    if (t >= batch.split_keep_fraction * std::get<0>(candidates.front())) out[id] = frame;
  return out;
}

// J^T J of a Jacobian in Ceres' compressed-row form, as a dense matrix. Each row of J has a
// handful of entries (a bearing touches one pose, one feature and the extrinsics), so the
// product is formed sparse: O(rows x 8^2) instead of the dense O(rows x cols^2). Hall zigzag,
// 318 tracks: filter (its bootstrap window) 12.97 -> 8.44 s, observability 2.62 -> 0.68 s.
Eigen::SparseMatrix<double> sparse_jacobian(const ceres::CRSMatrix& crs) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(crs.values.size());
  for (int r = 0; r < crs.num_rows; ++r)
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) t.emplace_back(r, crs.cols[k], crs.values[k]);
  Eigen::SparseMatrix<double> J(crs.num_rows, crs.num_cols);
  J.setFromTriplets(t.begin(), t.end());
  return J;
}

Eigen::MatrixXd information_from_jacobian(const ceres::CRSMatrix& crs) {
  const Eigen::SparseMatrix<double> J = sparse_jacobian(crs);
  const Eigen::SparseMatrix<double> F = J.transpose() * J;
  return Eigen::MatrixXd(F);
}

// The variables of the batch problem in the order of its Jacobian's columns: poses of frames
// 1..N (frame 0 is the gauge), features, extrinsics (the last three columns).
std::vector<double*> variable_blocks(Built& b) {
  std::vector<double*> v;
  for (std::size_t k = 1; k < b.poses.size(); ++k) v.push_back(b.poses[k].data());
  for (auto& [id, f] : b.features) v.push_back(f.data());
  for (auto& [id, bias] : b.biases) v.push_back(&bias);
  v.push_back(b.ex.data());
  return v;
}

// BatchNoiseCheck::wheels (WheelCheck): per frame, the wheels' rotation minus the solution's,
// with the variance eq. (31) gives the wheels' (K x batch inflation, composed over the frame's
// samples), fitted by weighted least squares as s x (the solution's rotation) + c x (distance
// rolled).
WheelCheck wheel_check(const Built& b,
                       const CalibrationRun& run,
                       const Options& options,
                       const BatchOptions& batch) {
  WheelCheck out;
  const double K = options.odometry_K * batch.odometry_inflation, e = options.wheel_base;
  if (!(e > 0.0)) return out;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  const std::size_t n = std::min(run.frames.size(), b.poses.size());
  for (std::size_t k = 1; k < n; ++k) {
    const FrameInput& f = run.frames[k];
    const double turn = (f.d_right - f.d_left) / e;  // eq. (15)
    const double dist = 0.5 * (f.d_right + f.d_left);
    if (turn == 0.0 && dist == 0.0) continue;
    double v;  // variance of (d_right - d_left)
    if (!f.covariance_per_K.isZero())
      v = K * (f.covariance_per_K(0, 0) + f.covariance_per_K(1, 1) - 2.0 * f.covariance_per_K(0, 1));
    else
      v = K * (std::abs(f.d_right) + std::abs(f.d_left));
    v = (v + 2.0 * options.odometry_variance_floor) / (e * e);
    if (!(v > 0.0)) continue;
    const double robot = angle_diff(b.poses[k][2], b.poses[k - 1][2]);
    const double r = angle_diff(turn, robot);
    const Eigen::Vector2d x(robot, dist);
    A += x * x.transpose() / v;
    g += x * r / v;
    ++out.frames;
  }
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(A);
  if (out.frames < 3 || ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0).all())
    return out;
  const Eigen::Vector2d ab = ldlt.solve(g);
  const Eigen::Matrix2d C = ldlt.solve(Eigen::Matrix2d::Identity());
  if (!ab.allFinite() || !C.allFinite()) return out;
  out.rotation_scale = ab(0);
  out.drift_per_m = ab(1);
  out.sigma_rotation_scale = std::sqrt(C(0, 0));
  out.sigma_drift_per_m = std::sqrt(C(1, 1));
  out.chi2 = ab.dot(A * ab);
  out.wheel_base = e;
  out.ok = true;
  return out;
}

// The error of the extrinsics measured by the data themselves (BatchNoiseCheck): at the
// solution theta^ of the whitened problem (residuals r, Jacobian J, Fisher information
// F = J^T J), the estimate's first-order error is -F^-1 J^T e for the true errors e. The
// extrinsics' rows of F^-1 are A (3 x n); the model covariance is A F A^T = [F^-1]_ee, which
// holds when every whitened error is independent with unit variance. The bearings of one
// track are not independent (an edge's position error changes slowly from frame to frame,
// and two nearly aligned lines pull a track's detections together), so the errors are
// summed per track before they are squared: the cluster-robust ("sandwich") covariance
// sum_c (A J_c^T r_c)(A J_c^T r_c)^T over clusters c (each track's bearings; each odometry
// factor). A track's own feature point absorbs the part of its errors along its own columns
// of J, and that part does not reach the extrinsics (A F_{:,f} = 0), so the fitted residuals
// stand in for the true errors up to the leverage of the shared variables.
BatchNoiseCheck noise_check(Built& b, int dense_limit) {
  BatchNoiseCheck out;
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable_blocks(b);
  eo.residual_blocks = b.odometry_blocks;
  eo.residual_blocks.insert(eo.residual_blocks.end(), b.bearing_blocks.begin(), b.bearing_blocks.end());
  // A track's bias prior (Options::track_bias_sigma) is a row of that track's cluster: without
  // it the bias is free and the check's information singular along it.
  for (const auto& [id, block] : b.bias_priors) eo.residual_blocks.push_back(block);
  eo.apply_loss_function = false;
  std::vector<double> r;
  ceres::CRSMatrix crs;
  if (!b.problem->Evaluate(eo, nullptr, &r, nullptr, &crs)) return out;
  const int m = crs.num_rows, n = crs.num_cols;
  if (m != static_cast<int>(r.size()) || n < 3) return out;
  // Cluster of each residual row: odometry factors (3 rows each) are their own clusters,
  // the bearings of a track one cluster. (Pieces of one line that the joins left apart are
  // not independent clusters. Grouped by a chain of Wald tests for the check (session 13),
  // they changed the verdicts of 1 in 25 runs from pixels with tracks broken every ~10
  // frames, and took 2 of the 3 "more noise" verdicts away: not kept.)
  std::vector<int> cluster(m);
  int row = 0, next = 0;
  for (std::size_t i = 0; i < b.odometry_blocks.size(); ++i, ++next)
    for (int k = 0; k < 3; ++k) cluster[row++] = next;
  std::map<int, int> of_track;
  auto track_cluster = [&of_track, &next](int id) {
    auto [it, fresh] = of_track.emplace(id, next);
    if (fresh) ++next;
    return it->second;
  };
  for (const auto& key : b.bearing_keys) cluster[row++] = track_cluster(key.first);
  for (const auto& [id, block] : b.bias_priors) cluster[row++] = track_cluster(id);
  if (row != m) return out;
  const Eigen::SparseMatrix<double> J = sparse_jacobian(crs);
  const Eigen::SparseMatrix<double> F = information_with_ridge(J);
  // F^-1 is needed column by column for every bearing (the leverage below). Below a few
  // thousand variables the dense inverse is the cheaper way (hall zigzag, 316 tracks, 1440
  // variables: the sparse solves took 60 s, their factor fills in); above, sparse solves.
  const bool dense = n <= dense_limit;
  Eigen::MatrixXd Finv;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  Eigen::MatrixXd At;  // n x 3: A^T
  if (dense) {
    const Eigen::LDLT<Eigen::MatrixXd> dl{Eigen::MatrixXd(F)};
    if (dl.info() != Eigen::Success) return out;
    Finv = dl.solve(Eigen::MatrixXd::Identity(n, n));
    if (!Finv.allFinite()) return out;
    At = Finv.rightCols(3);
  } else {
    ldlt.compute(F);
    if (ldlt.info() != Eigen::Success) return out;
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, 3);
    for (int k = 0; k < 3; ++k) E(n - 3 + k, k) = 1.0;
    At = ldlt.solve(E);
    if (ldlt.info() != Eigen::Success || !At.allFinite()) return out;
  }
  const Eigen::Matrix3d model = At.bottomRows<3>();
  const Eigen::MatrixXd U = J * At;  // m x 3: row i is A J_i^T
  std::vector<std::vector<int>> rows_of(next);
  for (int i = 0; i < m; ++i) rows_of[cluster[i]].push_back(i);
  const int first_track = static_cast<int>(b.odometry_blocks.size());
  Eigen::Matrix3d bearing_model = Eigen::Matrix3d::Zero();  // sum over bearing rows u_i u_i^T
  Eigen::Matrix3d clustered = Eigen::Matrix3d::Zero();
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Jr(J);
  for (int c = first_track; c < next; ++c) {
    const std::vector<int>& rows = rows_of[c];
    const int nc = static_cast<int>(rows.size());
    // Leverage of the track: H_cc = J_c F^-1 J_c^T. The fitted residuals are (I - H) e, and
    // the shared variables (poses, extrinsics) take up a good part of a track's errors (on
    // white synthetic bearings the plain sum gives a tenth of the model's covariance), so
    // (I - H_cc)^-1/2 r_c stands in for the track's errors (Bell and McCaffrey's bias-reduced
    // sandwich, "CR2": unbiased when the model is right; the jackknife's (I - H_cc)^-1 gave
    // 2.8 times the model's covariance on white bearings with 10 tracks).
    Eigen::MatrixXd H;
    if (dense) {
      // Only the variables the track touches (its feature, its frames' poses, the
      // extrinsics): H_cc = J_cS [F^-1]_SS J_cS^T.
      std::vector<int> cols;
      for (int k = 0; k < nc; ++k)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Jr, rows[k]); it; ++it)
          cols.push_back(static_cast<int>(it.col()));
      std::sort(cols.begin(), cols.end());
      cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
      const int ns = static_cast<int>(cols.size());
      Eigen::MatrixXd Jc = Eigen::MatrixXd::Zero(nc, ns);
      for (int k = 0; k < nc; ++k)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Jr, rows[k]); it; ++it)
          Jc(k, std::lower_bound(cols.begin(), cols.end(), static_cast<int>(it.col())) - cols.begin()) =
              it.value();
      Eigen::MatrixXd Fs(ns, ns);
      for (int a = 0; a < ns; ++a)
        for (int c2 = 0; c2 < ns; ++c2) Fs(a, c2) = Finv(cols[a], cols[c2]);
      H = Jc * Fs * Jc.transpose();
    } else {
      Eigen::MatrixXd JcT = Eigen::MatrixXd::Zero(n, nc);
      for (int k = 0; k < nc; ++k)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Jr, rows[k]); it; ++it)
          JcT(it.col(), k) = it.value();
      H = JcT.transpose() * ldlt.solve(JcT);
    }
    Eigen::VectorXd rc(nc);
    Eigen::MatrixXd Uc(nc, 3);
    for (int k = 0; k < nc; ++k) {
      rc(k) = r[rows[k]];
      Uc.row(k) = U.row(rows[k]);
    }
    bearing_model += Uc.transpose() * Uc;
    // The track's own feature point is determined by the track alone: along its two
    // directions I - H_cc is singular (r_c and the columns of U_c have no component there,
    // by the normal equations and A F_{:,f} = 0), so the inverse is taken on the complement.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eh(Eigen::MatrixXd::Identity(nc, nc) - H);
    Eigen::VectorXd inv = Eigen::VectorXd::Zero(nc);
    for (int k = 0; k < nc; ++k)
      if (eh.eigenvalues()(k) > 1e-6) inv(k) = 1.0 / std::sqrt(eh.eigenvalues()(k));
    const Eigen::VectorXd e =
        eh.eigenvectors() * inv.asDiagonal() * (eh.eigenvectors().transpose() * rc);
    const Eigen::Vector3d sc = Uc.transpose() * e;
    clustered += sc * sc.transpose();
  }
  const Eigen::LDLT<Eigen::Matrix3d> bi(bearing_model);
  if (bi.info() != Eigen::Success || !(bearing_model.trace() > 0.0)) return out;
  out.model_covariance = model;
  out.bearing_part = bearing_model;
  out.bearing_clustered = clustered;
  out.clusters = next - first_track;
  out.scale = bi.solve(clustered).trace() / 3.0;
  out.covariance = model + (out.scale - 1.0) * bearing_model;
  out.ok = std::isfinite(out.scale) && out.scale > 0.0;
  return out;
}

Built build(const CalibrationRun& run,
            const Options& options,
            const BatchPoint& at,
            const BatchOptions& batch,
            bool robust) {
  if (at.poses.size() != run.frames.size())
    throw InputError("batch: the starting point has " + std::to_string(at.poses.size()) +
                     " poses for " + std::to_string(run.frames.size()) + " frames");
  Built b;
  ceres::Problem::Options po;
  b.problem = std::make_unique<ceres::Problem>(po);
  b.poses.resize(at.poses.size());
  for (std::size_t k = 0; k < at.poses.size(); ++k)
    b.poses[k] = {at.poses[k](0), at.poses[k](1), at.poses[k](2)};
  b.ex = {at.extrinsics.phi, at.extrinsics.rho, at.extrinsics.psi};

  // Track lengths: only tracks long enough (and with a starting point) enter.
  std::map<int, int> length;
  for (const FrameInput& f : run.frames)
    for (const BearingObservation& o : f.observations) ++length[o.track_id];
  for (const auto& [id, n] : length) {
    auto it = at.features.find(id);
    if (n >= options.min_track_length && it != at.features.end() && it->second.allFinite())
      b.features[id] = {it->second(0), it->second(1)};
  }

  for (auto& p : b.poses) b.problem->AddParameterBlock(p.data(), 3);
  b.problem->SetParameterBlockConstant(b.poses[0].data());  // gauge: frame 0 is the origin
  b.problem->AddParameterBlock(b.ex.data(), 3);

  const double K = options.odometry_K * batch.odometry_inflation;
  for (std::size_t k = 1; k < run.frames.size(); ++k) {
    const FrameInput& f = run.frames[k];
    // Covariance of (d_right, d_left, lateral): eq. (31) over the frame's wheel samples
    // (compose_wheel_steps), or over the frame as one step; with the side slip allowed
    // (lateral_sigma) and the floor.
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    if (!f.covariance_per_K.isZero()) {
      S = K * f.covariance_per_K;
      S(0, 0) += options.odometry_variance_floor;
      S(1, 1) += options.odometry_variance_floor;
    } else {
      S.topLeftCorner<2, 2>() =
          chong_kleeman_covariance(f.d_right, f.d_left, K, options.odometry_variance_floor);
    }
    S(2, 2) += batch.lateral_sigma * batch.lateral_sigma;
    // W = L^-1 with S = L L^T: W^T W = S^-1.
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    const Eigen::Matrix3d W = llt.matrixL().solve(Eigen::Matrix3d::Identity());
    auto* cost = new ceres::AutoDiffCostFunction<OdometryResidual, 3, 3, 3>(
        new OdometryResidual{f.d_right, f.d_left, f.lateral, options.wheel_base, W});
    b.odometry_blocks.push_back(
        b.problem->AddResidualBlock(cost, nullptr, b.poses[k - 1].data(), b.poses[k].data()));
  }
  if (options.track_bias_sigma > 0.0)
    for (const auto& [id, f] : b.features) {
      double* bias = &(b.biases[id] = 0.0);
      b.bias_priors[id] = b.problem->AddResidualBlock(
          new ceres::AutoDiffCostFunction<BiasPrior, 1, 1>(
              new BiasPrior{1.0 / options.track_bias_sigma}),
          nullptr, bias);
    }
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    for (const BearingObservation& o : run.frames[k].observations) {
      auto it = b.features.find(o.track_id);
      if (it == b.features.end()) continue;
      const double inv_sigma = 1.0 / (options.bearing_sigma * o.sigma_scale);
      ceres::LossFunction* loss = robust ? new ceres::HuberLoss(batch.huber_sigmas) : nullptr;
      if (auto bias = b.biases.find(o.track_id); bias != b.biases.end())
        b.bearing_blocks.push_back(b.problem->AddResidualBlock(
            new ceres::AutoDiffCostFunction<BiasedBearingResidual, 1, 3, 2, 3, 1>(
                new BiasedBearingResidual{o.beta, inv_sigma}),
            loss, b.poses[k].data(), it->second.data(), b.ex.data(), &bias->second));
      else
        b.bearing_blocks.push_back(b.problem->AddResidualBlock(
            new ceres::AutoDiffCostFunction<BearingResidual, 1, 3, 2, 3>(
                new BearingResidual{o.beta, inv_sigma}),
            loss, b.poses[k].data(), it->second.data(), b.ex.data()));
      b.bearing_keys.emplace_back(o.track_id, static_cast<int>(k));
      ++b.num_bearings;
    }
  }
  return b;
}

BatchPoint point_of(const Built& b) {
  BatchPoint p;
  for (const auto& q : b.poses) p.poses.emplace_back(q[0], q[1], q[2]);
  for (const auto& [id, f] : b.features) p.features[id] = Eigen::Vector2d(f[0], f[1]);
  p.extrinsics = {wrap_angle(b.ex[0]), b.ex[1], wrap_angle(b.ex[2])};
  return p;
}

// One round of track splitting: `found` (find_splits, ids of `current`) is added to `splits`
// (tracker's ids, frames of the runs), the run is split again from `original` (split_tracks),
// and `at`, keyed by the ids of `current`, is re-keyed to the new run's ids, each new part
// starting where the part it came from was. Returns the new run; `origin` receives new id ->
// tracker's id. (The refinement and the filter's window.)
CalibrationRun split_round(const CalibrationRun& original,
                           const CalibrationRun& current,
                           const std::map<int, int>& found,
                           std::vector<std::pair<int, int>>* splits,
                           std::map<int, int>* origin,
                           BatchPoint* at) {
  for (const auto& [id, frame] : found) {
    const auto it = origin->find(id);
    splits->emplace_back(it != origin->end() ? it->second : id, frame);
  }
  std::map<int, int> next_origin;
  CalibrationRun next = split_tracks(original, *splits, &next_origin);
  // split_tracks only renames: observation i of frame k is the same bearing in both runs.
  std::map<int, Eigen::Vector2d> features;
  for (std::size_t k = 0; k < next.frames.size() && k < current.frames.size(); ++k) {
    const auto& a = next.frames[k].observations;
    const auto& c = current.frames[k].observations;
    for (std::size_t i = 0; i < a.size() && i < c.size(); ++i) {
      if (features.count(a[i].track_id)) continue;
      const auto f = at->features.find(c[i].track_id);
      if (f != at->features.end()) features[a[i].track_id] = f->second;
    }
  }
  at->features = std::move(features);
  *origin = std::move(next_origin);
  return next;
}

// Rounds of joining the pieces of one line (refinement and window), each on the problem
// solved again after the last.
constexpr int kMergeRounds = 10;

// One round of joining (find_merges) on the solved problem `b`: `run` renamed (join_tracks),
// `at` the solution with the joined pieces' points dropped (each line starts at its first
// piece's), the joins appended to *joins. Returns false when nothing joins.
bool merge_round(Built* b,
                 const Options& options,
                 CalibrationRun* run,
                 BatchPoint* at,
                 std::vector<std::pair<int, int>>* joins) {
  const std::vector<std::pair<int, int>> found =
      find_merges(b, options.max_missed_frames, chi2_quantile(options.gate_probability, 2));
  if (found.empty()) return false;
  *at = point_of(*b);
  std::map<int, int> renamed;
  *run = join_tracks(*run, found, &renamed);
  for (const auto& [id, into] : renamed) at->features.erase(id);
  joins->insert(joins->end(), found.begin(), found.end());
  return true;
}

// Options::track_bias_sigma: which bearings belong together (lines that cross, outliers,
// pieces of one line joined, tracks split where they slipped) is decided under the white
// model whose sigma is a bearing's whole error, sqrt(bearing_sigma^2 + track_bias_sigma^2);
// the estimate and its covariance under the model with the per-track bias, on the bearings
// those decisions kept (final_with_bias). With the bias in the decisions, a slip onto a
// neighbouring line was partly taken up by the slipped track's bias and left in: from pixels,
// office zigzag at 0.018 + 0.016 degree, 6 of 100 filter runs ended 0.25-0.36 degree off
// (NEES 10-24), the window having kept 36 more bearings in seed 65.
Options association_options(const Options& options) {
  Options a = options;
  a.bearing_sigma = std::hypot(options.bearing_sigma, options.track_bias_sigma);
  a.track_bias_sigma = 0.0;
  return a;
}

// The problem of `b`'s bearings (on `run`, the run its ids are of) with the per-track bias,
// from b's solution. `min_track_length`: of the problem that made the decisions.
Built final_with_bias(const CalibrationRun& run,
                      const Built& b,
                      const Options& options,
                      const BatchOptions& batch,
                      bool robust,
                      int min_track_length) {
  const std::set<std::pair<int, int>> keep(b.bearing_keys.begin(), b.bearing_keys.end());
  CalibrationRun kept = run;
  for (std::size_t k = 0; k < kept.frames.size(); ++k) {
    auto& obs = kept.frames[k].observations;
    obs.erase(std::remove_if(obs.begin(), obs.end(),
                             [&](const BearingObservation& o) {
                               return !keep.count({o.track_id, static_cast<int>(k)});
                             }),
              obs.end());
  }
  Options o = options;
  o.min_track_length = min_track_length;
  Built f = build(kept, o, point_of(b), batch, robust);
  f.guarded = b.guarded;
  return f;
}

}  // namespace

bool wheel_check_rejects_model(const WheelCheck& check, double level) {
  return check.ok && check.chi2 > chi2_quantile(1.0 - level, 2);
}

double noise_check_limit(int tracks, double level) {
  return chi2_quantile(1.0 - level, tracks) / tracks;
}

namespace {
// Whether a check can be judged at `level` (noise_check_rejects_model and
// noise_check_finds_less_noise).
bool judgeable(const BatchNoiseCheck& check, double level) {
  return check.ok && check.clusters >= 2 && level > 0.0 && level < 0.5;
}
}  // namespace

bool noise_check_rejects_model(const BatchNoiseCheck& check, double level) {
  return judgeable(check, level) && check.scale > noise_check_limit(check.clusters, level);
}

double noise_check_lower_limit(int tracks, double level) {
  return chi2_quantile(level, tracks) / tracks;
}

bool noise_check_finds_less_noise(const BatchNoiseCheck& check, double level) {
  return judgeable(check, level) && check.scale < noise_check_lower_limit(check.clusters, level);
}

NoiseVerdict noise_check_verdict(const BatchNoiseCheck& check, double level, double lower_level) {
  if (noise_check_rejects_model(check, level)) return NoiseVerdict::kMoreNoise;
  if (noise_check_finds_less_noise(check, lower_level)) return NoiseVerdict::kLessNoise;
  return NoiseVerdict::kAgrees;
}

std::vector<Eigen::Vector3d> dead_reckoning(const CalibrationRun& run, double wheel_base) {
  std::vector<Eigen::Vector3d> poses;
  poses.reserve(run.frames.size());
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    if (k > 0) {
      const FrameInput& f = run.frames[k];
      p = integrate_pose_lateral(p, f.d_right, f.d_left, f.lateral, wheel_base);
    }
    poses.push_back(p);
  }
  return poses;
}

BatchPoint batch_point_from_filter(const CalibrationRun& run,
                                   const Options& options,
                                   const FilterResult& filter) {
  BatchPoint b;
  b.poses = dead_reckoning(run, options.wheel_base);
  b.extrinsics = filter.extrinsics;
  for (const auto& [id, t] : filter.tracks) {
    if (t.frame < 0 || t.frame >= static_cast<int>(b.poses.size())) continue;
    b.features[id] = feature_to_world(b.poses[t.frame], t.D_theta(0), t.D_theta(1));
  }
  return b;
}

RefinementResult refine_batch(const CalibrationRun& run,
                              const Options& options,
                              const BatchPoint& start,
                              const BatchOptions& batch) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  // The decisions under the bearing's whole error; the bias, when modelled, at the end
  // (association_options).
  const Options& model = options;
  const Options assoc = association_options(model);
  Built b = build(run, assoc, start, batch, batch.robust);
  RefinementResult res;
  res.num_bearings = b.num_bearings;

  ceres::Solver::Options so;
  // Sparse Cholesky of the whole normal equations: the poses form a chain and each feature
  // ties many poses, so the Schur complement on either is nearly dense. Hall zigzag, 252
  // frames and 114 tracks in the filter's window: 17.7 s against 40.8 s with SPARSE_SCHUR,
  // the same solution.
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  so.max_num_iterations = batch.max_iterations;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, b.problem.get(), &summary);
  // Outlying bearings (false matches) out, at the filter's gate, then solve again.
  const double gate = std::sqrt(chi2_quantile(options.gate_probability, 1));
  std::map<int, int> origin;  // id given by a split -> the tracker's id
  auto reject_and_solve = [&] {
    // Bearings where lines cross out first (the outliers are judged without them).
    if (reject_crossings(&b, options.crossing_guard, options.max_missed_frames, 2, origin,
                         chi2_quantile(options.gate_probability, 2)) > 0)
      ceres::Solve(so, b.problem.get(), &summary);
    res.num_rejected = 0;
    if (drop_collapsed_features(&b, options.min_feature_range) > 0)
      ceres::Solve(so, b.problem.get(), &summary);
    for (int round = 0; round < 3; ++round) {
      // Two bearings at least determine a feature point.
      const int n = reject_outliers(&b, gate, 2);
      res.num_rejected += n;
      if (n == 0) break;
      ceres::Solve(so, b.problem.get(), &summary);
    }
  };
  reject_and_solve();
  // Pieces of one line joined (the tracker lost the line and found it again under a new
  // id), and the problem built and solved again, each line starting at its first piece's
  // point.
  CalibrationRun merged = run;
  for (int round = 0; batch.merge_pieces && round < kMergeRounds; ++round) {
    BatchPoint at;
    if (!merge_round(&b, assoc, &merged, &at, &res.merges)) break;
    b = build(merged, assoc, at, batch, batch.robust);
    ceres::Solve(so, b.problem.get(), &summary);
    reject_and_solve();
  }
  // Tracks that slipped onto a neighbouring line are split in two and the problem is built
  // and solved again from the current solution (all bearings back in, outliers re-judged).
  CalibrationRun split_run;
  for (int round = 0; batch.split_chi2 > 0.0 && round < batch.split_rounds; ++round) {
    const std::map<int, int> found = find_splits(b, batch);
    if (found.empty()) break;
    BatchPoint at = point_of(b);
    split_run =
        split_round(merged, round == 0 ? merged : split_run, found, &res.splits, &origin, &at);
    res.num_splits += static_cast<int>(found.size());
    b = build(split_run, assoc, at, batch, batch.robust);
    ceres::Solve(so, b.problem.get(), &summary);
    reject_and_solve();
  }
  if (res.num_splits > 0)
    res.solved_run = std::move(split_run);
  else if (!res.merges.empty())
    res.solved_run = std::move(merged);
  if (model.track_bias_sigma > 0.0) {
    b = final_with_bias(res.renamed() ? res.solved_run : run, b, model, batch, batch.robust, 2);
    ceres::Solve(so, b.problem.get(), &summary);
  }
  res.guarded = b.guarded;
  res.rejected = unused_bearings(res.renamed() ? res.solved_run : run, b, [](int id) { return id; });
  res.num_bearings = b.num_bearings;
  res.num_features = static_cast<int>(b.features.size());
  {
    // Bearing residuals at the solution, in radians (their scatter is the bearing noise the
    // data really has: calibrate() can estimate the bearing sigma from it).
    // Robust scale (1.4826 x median |r|: false matches left inside the gate do not inflate
    // it), corrected for the parameters fitted (2 per feature, 3 extrinsics).
    std::vector<double> a;
    a.reserve(b.bearing_blocks.size());
    for (ceres::ResidualBlockId id : b.bearing_blocks) {
      double r = 0.0, cost = 0.0;
      b.problem->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, &r, nullptr);
      a.push_back(std::abs(r));
    }
    const int dof = b.num_bearings - 2 * res.num_features - 3;
    if (dof > 0 && !a.empty()) {
      std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
      const double mad = 1.4826 * a[a.size() / 2];
      res.bearing_residual_sigma =
          mad * std::sqrt(static_cast<double>(a.size()) / dof) * options.bearing_sigma;
    }
  }
  res.noise = noise_check(b, batch.noise_check_dense_limit);
  res.noise.wheels = wheel_check(b, run, options, batch);
  res.converged = summary.termination_type == ceres::CONVERGENCE;
  res.initial_cost = summary.initial_cost;
  res.final_cost = summary.final_cost;
  res.iterations = static_cast<int>(summary.iterations.size());
  res.report = summary.BriefReport();
  // (phi, rho, psi) and (phi + pi, -rho, psi - pi) place the camera identically (eq. 16-17):
  // the solver may end on the second (seen from pixels, a start far from the truth); the
  // answer is given with rho >= 0 and the angles wrapped, and the covariance below is
  // computed there.
  if (b.ex[1] < 0.0) {
    b.ex[0] += kPi;
    b.ex[1] = -b.ex[1];
    b.ex[2] -= kPi;
  }
  b.ex[0] = wrap_angle(b.ex[0]);
  b.ex[2] = wrap_angle(b.ex[2]);
  res.solution = point_of(b);
  res.extrinsics = res.solution.extrinsics;

  // Covariance of (phi, rho, psi): the inverse of the Fisher information at the solution
  // (of the problem without robust loss, as it is the Gaussian model's bound), marginal.
  ceres::Covariance::Options co;
  // Sparse QR: fails on a rank-deficient problem (then the caller falls back on the
  // observability analysis). DENSE_SVD gave the same covariance to 13 digits but took 15 s
  // on the hall zigzag (1440 variables) against 0.15 s.
  co.algorithm_type = ceres::SPARSE_QR;
  co.min_reciprocal_condition_number = 1e-14;
  co.null_space_rank = 0;
  co.num_threads = 1;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks = {{b.ex.data(), b.ex.data()}};
  // A rank-deficient problem is an expected outcome here (the caller falls back on the
  // observability analysis), not an error for the user's terminal: Ceres' own log line
  // ("Covariance matrix is near rank deficient ...") is silenced for this call.
  const int saved_min_log_level = FLAGS_minloglevel;
  FLAGS_minloglevel = google::GLOG_FATAL;
  const bool cov_ok = cov.Compute(blocks, b.problem.get());
  FLAGS_minloglevel = saved_min_log_level;
  if (cov_ok) {
    double C[9];
    cov.GetCovarianceBlock(b.ex.data(), b.ex.data(), C);
    res.covariance = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(C);
    res.covariance_ok = res.covariance.allFinite();
  }
  return res;
}

ObservabilityReport analyse_observability(const CalibrationRun& run,
                                          const Options& options,
                                          const BatchPoint& at,
                                          const BatchOptions& batch,
                                          const ObservabilityOptions& obs) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  Built b = build(run, options, at, batch, /*robust=*/false);
  // The Jacobian of the whitened residuals: Fisher information F = J^T J (the residuals are
  // already divided by their sigmas). Frame 0 is not a variable (gauge).
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = variable_blocks(b);
  eo.apply_loss_function = false;
  ceres::CRSMatrix crs;
  b.problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs);
  const Eigen::MatrixXd F = information_from_jacobian(crs);
  const int n = static_cast<int>(F.rows()), no = n - 3;

  // Marginal information of the extrinsics: Schur complement of the nuisance block
  // (pseudo-inverse, so that features without parallax do not poison it). The nuisance
  // variables are scaled to unit information first (Jacobi): poses, features in metres and
  // bearings whitened by a small sigma span many orders of magnitude, and unscaled, the
  // pseudo-inverse's cut (relative to the largest eigenvalue) dropped the depth of a feature
  // seen with little parallax while its coupling to the extrinsics stayed: the bound of
  // phi + psi came out 2.2 times too small (corridor paper seeds 9, 10: 1.3e-4 rad against
  // 2.9e-4 from the full inverse; errors 6.4e-4 and 5.1e-4).
  Eigen::VectorXd scale(no);
  for (int i = 0; i < no; ++i) scale(i) = F(i, i) > 0.0 ? 1.0 / std::sqrt(F(i, i)) : 1.0;
  const Eigen::MatrixXd Foo = scale.asDiagonal() * F.topLeftCorner(no, no) * scale.asDiagonal();
  const Eigen::MatrixXd Foe = scale.asDiagonal() * F.topRightCorner(no, 3);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Foo);
  const Eigen::VectorXd& lam = es.eigenvalues();
  const double lmax = lam.cwiseAbs().maxCoeff();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(no);
  for (int i = 0; i < no; ++i)
    if (lam(i) > 1e-14 * lmax) inv(i) = 1.0 / lam(i);
  const Eigen::MatrixXd UtFoe = es.eigenvectors().transpose() * Foe;
  Eigen::Matrix3d S = F.bottomRightCorner<3, 3>() - UtFoe.transpose() * inv.asDiagonal() * UtFoe;
  S = 0.5 * (S + S.transpose()).eval();

  ObservabilityReport rep;
  rep.information = S;
  // Scale by the thresholds so that "determined" is "[S~^-1]_ii < 1".
  const Eigen::Vector3d thr(obs.max_sigma_angle, obs.max_sigma_rho, obs.max_sigma_angle);
  const Eigen::Matrix3d St = thr.asDiagonal() * S * thr.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e3(St);
  rep.eigenvalues = e3.eigenvalues();
  const double emax = std::max(rep.eigenvalues.maxCoeff(), 0.0);
  const double floor = obs.relative_eigenvalue_floor * std::max(emax, 1e-300);
  rep.rank = 0;
  for (int i = 0; i < 3; ++i) rep.rank += rep.eigenvalues(i) > floor ? 1 : 0;
  rep.condition = rep.eigenvalues(0) > floor ? emax / rep.eigenvalues(0)
                                             : std::numeric_limits<double>::infinity();
  const double inf = std::numeric_limits<double>::infinity();
  // Variance of v^T (phi, rho, psi) (v in unscaled units) = sum (v~ . u_k)^2 / lambda_k,
  // infinite when v has a component along a (numerically) null eigenvector.
  auto sigma_of = [&](const Eigen::Vector3d& v) {
    const Eigen::Vector3d vt = v.cwiseProduct(thr);  // S^-1 = T S~^-1 T
    double var = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double c = vt.dot(e3.eigenvectors().col(k));
      if (rep.eigenvalues(k) <= floor) {
        if (std::abs(c) > 1e-6 * vt.norm()) return inf;
        continue;
      }
      var += c * c / rep.eigenvalues(k);
    }
    return std::sqrt(var);
  };
  auto verdict = [&](const Eigen::Vector3d& v, double threshold) {
    ParameterVerdict p;
    p.crlb = sigma_of(v);
    p.determined = p.crlb < threshold;
    return p;
  };
  const Extrinsics& ex = at.extrinsics;
  rep.phi = verdict({1, 0, 0}, obs.max_sigma_angle);
  rep.rho = verdict({0, 1, 0}, obs.max_sigma_rho);
  rep.psi = verdict({0, 0, 1}, obs.max_sigma_angle);
  rep.yaw = verdict({1, 0, 1}, obs.max_sigma_angle);
  rep.x = verdict({-ex.rho * std::sin(ex.phi), std::cos(ex.phi), 0}, obs.max_sigma_rho);
  rep.y = verdict({ex.rho * std::cos(ex.phi), std::sin(ex.phi), 0}, obs.max_sigma_rho);
  // Did the robot turn (Sec. 8.1)? Its heading's span against the heading noise of eq. (31)
  // accumulated over the run: below min_rotation_sigmas, the information about phi, rho and
  // psi individually comes from the estimated trajectory's noise, not from a turn.
  {
    double lo = 0.0, hi = 0.0, var = 0.0;
    for (std::size_t k = 0; k < at.poses.size(); ++k) {
      lo = std::min(lo, at.poses[k](2) - at.poses[0](2));
      hi = std::max(hi, at.poses[k](2) - at.poses[0](2));
    }
    const double K = options.odometry_K * batch.odometry_inflation;
    for (const FrameInput& f : run.frames) var += K * (std::abs(f.d_right) + std::abs(f.d_left));
    rep.heading_range = hi - lo;
    rep.heading_noise = std::sqrt(var) / options.wheel_base;
    if (rep.heading_range < obs.min_rotation_sigmas * rep.heading_noise)
      for (ParameterVerdict* p : {&rep.phi, &rep.rho, &rep.psi, &rep.x, &rep.y}) p->determined = false;
  }
  if (rep.rank == 3) {
    rep.crlb_covariance = S.ldlt().solve(Eigen::Matrix3d::Identity());
  } else {
    rep.crlb_covariance.setConstant(inf);
  }

  std::ostringstream m;
  if (rep.all_determined()) {
    m << "phi, rho and psi are determined by this trajectory (Cramer-Rao bounds: phi "
      << rad2deg(rep.phi.crlb) << " deg, rho " << 1e3 * rep.rho.crlb << " mm, psi "
      << rad2deg(rep.psi.crlb) << " deg).";
  } else {
    std::vector<std::string> bad;
    if (!rep.phi.determined) bad.push_back("phi");
    if (!rep.rho.determined) bad.push_back("rho");
    if (!rep.psi.determined) bad.push_back("psi");
    for (std::size_t i = 0; i < bad.size(); ++i)
      m << (i == 0 ? "" : (i + 1 == bad.size() ? " and " : ", ")) << bad[i];
    m << (bad.size() == 1 ? " is" : " are") << " not determined by this trajectory";
    if (rep.yaw.determined)
      m << " (the camera yaw phi + psi is, to " << rad2deg(rep.yaw.crlb)
        << " deg): the camera's position on the robot shows only while the robot turns, and "
           "this run did not turn enough";
    if (rep.yaw.determined && rep.heading_range < obs.min_rotation_sigmas * rep.heading_noise)
      m << " (its heading spans " << rad2deg(rep.heading_range)
        << " deg, within the wheels' noise of " << rad2deg(rep.heading_noise) << " deg)";
    if (rep.yaw.determined)
      m << ". Add a turn in place near features (1-3 m away), or alternate straights and turns "
           "(Sec. 8.1).";
    else
      m << ", not even the camera yaw phi + psi: drive a straight line with vertical lines "
           "around (a few meters away), then turn in place near them (Sec. 8.1).";
  }
  rep.message = m.str();
  return rep;
}

}  // namespace omnivert::calib

namespace omnivert::calib {

namespace {

// Ext prior: (phi, rho, psi) ~ N(prior, diag(sigma^2)), angles wrapped.
struct ExtrinsicsPrior {
  Eigen::Vector3d mean, inv_sigma;
  template <typename T>
  bool operator()(const T* ex, T* r) const {
    const T dphi = ex[0] - mean(0), dpsi = ex[2] - mean(2);
    r[0] = atan2(sin(dphi), cos(dphi)) * inv_sigma(0);
    r[1] = (ex[1] - mean(1)) * inv_sigma(1);
    r[2] = atan2(sin(dpsi), cos(dpsi)) * inv_sigma(2);
    return true;
  }
};

// Inverse-depth prior of a track: 1 / |f - C| ~ N(q0, (scale sigma_q)^2), C the camera centre
// at the track's first frame. Weak (scale 100 by default): it only keeps a track without
// parallax in the window finite. (At full strength it biases the distant features of the
// paper's setup, q0 being a midpoint, and the window with them: measured 1 run in 20 with
// NEES ~ 500.)
struct InverseDepthPrior {
  double q0, inv_sigma;
  template <typename T>
  bool operator()(const T* pose, const T* f, const T* ex, T* r) const {
    const T a = pose[2] + ex[0];
    const T dx = f[0] - (pose[0] + ex[1] * cos(a));
    const T dy = f[1] - (pose[1] + ex[1] * sin(a));
    r[0] = (T(1.0) / sqrt(dx * dx + dy * dy) - q0) * inv_sigma;
    return true;
  }
};

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

double camera_yaw_from_flow(const CalibrationRun& run,
                            double wheel_base,
                            int min_pairs,
                            double min_explained) {
  // Each bearing pair of one track in consecutive frames: d_alpha = d_beta + d_theta (the
  // world direction's change, the wheels' turn put back; eq. 30), against the signed distance
  // driven ds. Along a straight, a point at distance h from the line of travel turns at
  // d_alpha / ds = sin(x) |sin(x)| / h, x = beta + yaw its bearing from the direction of
  // travel (which is at -yaw in the camera's frame). For a given yaw each track's 1/h on each
  // straight is a one-dimensional least-squares fit; the yaw is the one whose fits explain the
  // most of sum(d_alpha^2): a grid of 0.5 degree, then a parabola through the best three.
  // (Without 1/h, one sum over all tracks leaned by 0.27 rad on the synthetic paper run; with
  // 1/|d| instead of 1/h, by 0.25.)
  struct Pair {
    double ds, dalpha, sin_beta, cos_beta;  // beta: the pair's mid bearing
  };
  std::map<std::pair<int, int>, std::vector<Pair>> tracks;  // (track id, straight) -> pairs
  double total = 0.0;
  int pairs = 0;
  int straight = 0;  // counts the frames that turn: a track's h is that of one straight
  std::map<int, double> previous;  // track id -> bearing in the previous frame
  for (const FrameInput& f : run.frames) {
    const Vec2 step = wheel_step(f.d_right, f.d_left, wheel_base);  // eq. (15)
    const double ds = step(0), dtheta = step(1);
    if (std::abs(dtheta) * wheel_base > std::abs(ds)) ++straight;  // wheels turning, not driving
    std::map<int, double> now;
    for (const BearingObservation& o : f.observations) {
      now[o.track_id] = o.beta;
      const auto it = previous.find(o.track_id);
      if (it == previous.end() || ds == 0.0) continue;
      const double dbeta = wrap_angle(o.beta - it->second);
      const double dalpha = dbeta + dtheta;
      if (!std::isfinite(dalpha) || std::abs(dalpha) > 0.1) continue;  // a switch of lines
      const double mid = it->second + 0.5 * dbeta;
      tracks[{o.track_id, straight}].push_back({ds, dalpha, std::sin(mid), std::cos(mid)});
      total += dalpha * dalpha;
      ++pairs;
    }
    previous = std::move(now);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (pairs < min_pairs || !(total > 0.0)) return nan;
  auto explained = [&tracks](double yaw) {
    const double sy = std::sin(yaw), cy = std::cos(yaw);
    double g = 0.0;
    for (const auto& [id, v] : tracks) {
      double sxy = 0.0, sxx = 0.0;
      for (const Pair& p : v) {
        const double sx = p.sin_beta * cy + p.cos_beta * sy;  // sin(beta + yaw)
        const double x = p.ds * sx * std::abs(sx);
        sxy += p.dalpha * x;
        sxx += x * x;
      }
      if (sxy > 0.0 && sxx > 0.0) g += sxy * sxy / sxx;
    }
    return g;
  };
  constexpr int kGrid = 720;
  std::array<double, kGrid> g{};
  int best = 0;
  for (int i = 0; i < kGrid; ++i) {
    g[static_cast<std::size_t>(i)] = explained(-kPi + 2.0 * kPi * i / kGrid);
    if (g[static_cast<std::size_t>(i)] > g[static_cast<std::size_t>(best)]) best = i;
  }
  if (g[static_cast<std::size_t>(best)] < min_explained * total) return nan;
  const double gm = g[static_cast<std::size_t>((best + kGrid - 1) % kGrid)];
  const double g0 = g[static_cast<std::size_t>(best)];
  const double gp = g[static_cast<std::size_t>((best + 1) % kGrid)];
  const double curvature = gm - 2.0 * g0 + gp;
  const double offset = curvature < 0.0 ? 0.5 * (gm - gp) / curvature : 0.0;
  return wrap_angle(-kPi + 2.0 * kPi * (best + std::clamp(offset, -0.5, 0.5)) / kGrid);
}

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
    if (reject_crossings(&b, options.crossing_guard, options.max_missed_frames, 1, to_tracker(),
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
    split_window = split_round(merged_window, round == 0 ? merged_window : split_window, found,
                               &window_splits, &origin, &at);
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
    for (const auto& [id, k] : b.guarded) details->guarded.emplace_back(tracker_of_bearing(id, k), k);
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

std::map<int, int> join_roots(const std::vector<std::pair<int, int>>& joins) {
  std::map<int, int> earlier;  // joined piece -> the piece it continues
  auto root_of = [&earlier](int x) {
    for (auto it = earlier.find(x); it != earlier.end(); it = earlier.find(x)) x = it->second;
    return x;
  };
  // A piece's last join is the one kept (the pairs are taken from the last), and a join that
  // would close a loop is left out, so the chains end. The window reports its joins by the
  // tracker's ids, and two pieces of one tracker id (parted at a gap or a slip, then joined)
  // gave (T, T), or T -> U -> T: the chain never ended (corridor zigzag seed 28 with
  // --track-bias-sigma hung here). Where the pairs make no loop this is what it was.
  for (auto it = joins.rbegin(); it != joins.rend(); ++it) {
    const auto& [a, c] = *it;
    if (a == c || earlier.count(c) || root_of(a) == c) continue;
    earlier[c] = a;
  }
  std::map<int, int> root;
  for (const auto& [c, a] : earlier) root[c] = root_of(a);
  return root;
}

CalibrationRun join_tracks(const CalibrationRun& run,
                           const std::vector<std::pair<int, int>>& joins,
                           std::map<int, int>* renamed) {
  std::map<int, int> root = join_roots(joins);
  CalibrationRun out = run;
  for (FrameInput& f : out.frames)
    for (BearingObservation& o : f.observations)
      if (const auto it = root.find(o.track_id); it != root.end()) o.track_id = it->second;
  if (renamed) *renamed = std::move(root);
  return out;
}

CalibrationRun split_tracks(const CalibrationRun& run,
                            const std::vector<std::pair<int, int>>& splits,
                            std::map<int, int>* origin) {
  if (origin) origin->clear();
  if (splits.empty()) return run;
  int next_id = 0;
  for (const FrameInput& f : run.frames)
    for (const BearingObservation& o : f.observations) next_id = std::max(next_id, o.track_id + 1);
  // Per track, its split frames in order, and the id of the part starting at each.
  std::map<int, std::map<int, int>> parts;
  for (const auto& [id, frame] : splits) parts[id].emplace(frame, 0);
  for (auto& [id, starts] : parts)
    for (auto& [frame, nid] : starts) {
      nid = next_id++;
      if (origin) (*origin)[nid] = id;
    }
  CalibrationRun out = run;
  for (std::size_t k = 0; k < out.frames.size(); ++k)
    for (BearingObservation& o : out.frames[k].observations) {
      const auto it = parts.find(o.track_id);
      if (it == parts.end()) continue;
      auto p = it->second.upper_bound(static_cast<int>(k));  // first split after frame k
      if (p == it->second.begin()) continue;                  // before the first split
      o.track_id = std::prev(p)->second;
    }
  return out;
}

}  // namespace omnivert::calib
