#include "omnivert/match/tracker.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {
namespace {

// Capacity for a frame of n lines: at least 64 (frames have 20-40 lines), else the next power
// of two, so that buffers reach their final size after a few frames and then stay.
Eigen::Index line_capacity(Eigen::Index n) {
  return std::max<Eigen::Index>(64,
                                static_cast<Eigen::Index>(std::bit_ceil(
                                    static_cast<std::size_t>(std::max<Eigen::Index>(n, 1)))));
}

}  // namespace

bool TrackerOptions::IsValid(std::string* error) const {
  if (!match.IsValid(error)) return false;
  if (look_back < 1 || look_back > 1000) {
    if (error) *error = "look-back must be between 1 and 1000 frames (paper: 20)";
    return false;
  }
  if (!(continuity_tolerance >= 0.0 && continuity_tolerance < kPi)) {
    if (error) *error = "continuity tolerance must be in [0, pi) radians (0: off)";
    return false;
  }
  if (!(continuity_path_curvature >= 0.0 && continuity_turn_curvature >= 0.0 &&
        std::isfinite(continuity_path_curvature) && std::isfinite(continuity_turn_curvature))) {
    if (error) *error = "continuity curvature bounds must be finite and >= 0";
    return false;
  }
  if (!(confirm_f1 >= 0.0 && std::isfinite(confirm_f1) && confirm_tolerance >= 0.0 &&
        confirm_tolerance < kPi)) {
    if (error) *error = "confirmed F1 must be >= 0 (0: off) and its tolerance in [0, pi) radians";
    return false;
  }
  if (!(look_back_f1 >= 0.0 && std::isfinite(look_back_f1))) {
    if (error) *error = "look-back F1 must be >= 0 (0: F1)";
    return false;
  }
  return gate.IsValid(error);
}

TrackerOptions paper_tracker_options() { return TrackerOptions{}; }

TrackerOptions recommended_tracker_options(double wheel_base) {
  TrackerOptions o;
  o.mutual = true;
  o.same_polarity = true;
  // Measured on the rendered tours (docs/tracking.md Sec. 6): track continuity with the track
  // model at 0.8 degree, F1 0.6 and 0.5 across a look-back gap.
  o.continuity_tolerance = deg2rad(0.8);  // used when the gate (odometry) is on
  o.continuity_model = TrackerOptions::ContinuityModel::kTrack;
  o.match.f1 = 0.6;
  o.look_back_f1 = 0.5;
  // Confirmed F1 (docs/tracking.md Sec. 3): with the finer peaks of extraction (session 5) it
  // brings the corridor's false new entries under target at little cost in false matches.
  o.confirm_f1 = 1.05;
  o.confirm_tolerance = deg2rad(0.3);
  if (wheel_base > 0.0) {
    o.gate.enabled = true;
    o.gate.wheel_base = wheel_base;
  }
  return o;
}

const char* to_string(LinkVerdict v) {
  switch (v) {
    case LinkVerdict::kLinked:
      return "linked";
    case LinkVerdict::kNoFrame:
      return "no-frame";
    case LinkVerdict::kNoCandidates:
      return "no-candidates";
    case LinkVerdict::kTest1:
      return "test1";
    case LinkVerdict::kTest2:
      return "test2";
    case LinkVerdict::kTest3:
      return "test3";
    case LinkVerdict::kLookBackF1:
      return "look-back-f1";
    case LinkVerdict::kMutual:
      return "mutual";
    case LinkVerdict::kClaimed:
      return "claimed";
    case LinkVerdict::kGate:
      return "gate";
    case LinkVerdict::kContinuity:
      return "continuity";
    case LinkVerdict::kFork:
      return "fork";
  }
  return "?";
}

std::string TrackerStats::BriefReport() const {
  std::ostringstream s;
  s << frames << " frames, " << lines << " lines: " << matched_previous
    << " matched in the previous frame, " << matched_look_back << " by look-back, " << new_tracks
    << " new tracks; rejected: test1 " << rejected_test1 << ", test2 " << rejected_test2
    << ", test3 " << rejected_test3 << ", mutual " << rejected_mutual << ", claimed "
    << rejected_claimed << ", odometry gate " << rejected_gate << ", continuity "
    << rejected_continuity << ", fork " << rejected_fork;
  return s.str();
}

Tracker::Tracker(TrackerOptions options) : options_(options), matcher_(options.match) {
  // Options usually come from the user (flags, config): report, do not crash.
  std::string error;
  if (!options_.IsValid(&error)) throw InputError("tracker options: " + error);
  ring_.resize(static_cast<std::size_t>(options_.look_back));
}

Tracker::Slot& Tracker::slot_back(int k) {
  const std::int64_t frame = frame_count_ - k;
  assert(k >= 1 && k <= options_.look_back && frame >= 0);
  return ring_[static_cast<std::size_t>(frame % options_.look_back)];
}

const Tracker::Slot& Tracker::slot_back(int k) const {
  return const_cast<Tracker*>(this)->slot_back(k);
}

bool Tracker::track_claimed(std::int64_t id) const {
  return std::find(claimed_.begin(), claimed_.end(), id) != claimed_.end();
}

void Tracker::add_frame(const FrameFeatures& frame, std::vector<TrackAssignment>* out) {
  if (options_.gate.enabled) {
    throw std::invalid_argument("Tracker::add_frame: the odometry gate needs wheel increments");
  }
  add_frame(frame, WheelIncrement{}, out);
}

void Tracker::add_frame(const FrameFeatures& frame,
                        const WheelIncrement& since_previous,
                        std::vector<TrackAssignment>* out) {
  const int n = static_cast<int>(frame.lines.size());
  // Contract: one descriptor row per line, one width for the whole run.
  if (frame.descriptors.rows() != n) {
    throw std::invalid_argument("Tracker::add_frame: " + std::to_string(n) + " lines but " +
                                std::to_string(frame.descriptors.rows()) + " descriptor rows");
  }
  if (n > 0 && descriptor_width_ > 0 && frame.descriptors.cols() != descriptor_width_) {
    throw std::invalid_argument("Tracker::add_frame: descriptor width changed from " +
                                std::to_string(descriptor_width_) + " to " +
                                std::to_string(frame.descriptors.cols()));
  }
  if (n > 0) descriptor_width_ = frame.descriptors.cols();
  if (frame_count_ > 0 && options_.gate.enabled) {
    odometry_.add(since_previous, options_.gate.wheel_base);
  }
  out->assign(static_cast<std::size_t>(n), TrackAssignment{});
  claimed_.clear();
  if (static_cast<Eigen::Index>(unmatched_.capacity()) < n) {
    const auto cap = static_cast<std::size_t>(line_capacity(n));
    unmatched_.reserve(cap);
    rates_.reserve(cap);
    turn_rates_.reserve(cap);
    still_unmatched_.reserve(cap);
    claimed_.reserve(cap);
  }
  unmatched_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) unmatched_[static_cast<std::size_t>(i)] = i;

  const int held = static_cast<int>(std::min<std::int64_t>(frame_count_, options_.look_back));
  for (int k = 1; k <= held && !unmatched_.empty(); ++k) {
    Slot& slot = slot_back(k);
    if (slot.num_lines == 0) continue;
    const auto candidates = slot.descriptors.topRows(slot.num_lines);
    // Query rows: the lines still unmatched (all of them for k = 1).
    const int nq = static_cast<int>(unmatched_.size());
    // All lines still in play (always so for k = 1): match the frame's own matrix, no copy.
    const bool all_rows = nq == n;
    if (all_rows) {
      matcher_.match(frame.descriptors, candidates, &results_);
    } else {
      if (query_.rows() < nq || query_.cols() != frame.descriptors.cols()) {
        query_.resize(line_capacity(std::max<Eigen::Index>(query_.rows(), nq)),
                      frame.descriptors.cols());
      }
      for (int q = 0; q < nq; ++q) {
        query_.row(q) = frame.descriptors.row(unmatched_[static_cast<std::size_t>(q)]);
      }
      matcher_.match(query_.topRows(nq), candidates, &results_);
    }
    const BearingGate gate = options_.gate.enabled
                                 ? make_bearing_gate(options_.gate, slot.odometry, odometry_)
                                 : BearingGate{};
    const bool gate_restricts =
        options_.gate.enabled && options_.gate_candidates && gate.informative;
    const bool restrict = gate_restricts || options_.same_polarity;
    // Whether line `a` of the new frame may be matched to line `j` of frame t-k.
    auto admissible = [&](int a, int j) {
      const VerticalLine& l = frame.lines[static_cast<std::size_t>(a)];
      if (options_.same_polarity) {
        const int pj = slot.polarities[static_cast<std::size_t>(j)];
        if (l.polarity != 0 && pj != 0 && l.polarity != pj) return false;
      }
      return !gate_restricts || gate.admits(slot.bearings[static_cast<std::size_t>(j)], l.bearing);
    };
    if (restrict) {
      // Tests 1 and 3 among the admissible candidates; test 2's mean over all of them.
      const auto d = matcher_.last_distances();
      const int nc = static_cast<int>(slot.num_lines);
      for (int q = 0; q < nq; ++q) {
        const int line = unmatched_[static_cast<std::size_t>(q)];
        MatchResult& r = results_[static_cast<std::size_t>(q)];
        float best = std::numeric_limits<float>::infinity(), second = best;
        int best_j = -1, admitted = 0;
        for (int j = 0; j < nc; ++j) {
          if (!admissible(line, j)) continue;
          ++admitted;
          const float v = d(q, j);
          if (v < best) {
            second = best;
            best = v;
            best_j = j;
          } else if (v < second) {
            second = v;
          }
        }
        if (admitted == 0) {
          if (r.accepted()) ++stats_.rejected_gate;
          r.best = -1;
          r.verdict = MatchVerdict::kNoCandidates;
          continue;
        }
        r.best = best_j;
        r.min_distance = best;
        r.second_distance = second;
        // N_B = all lines of the frame (test 2's mean over them); with one admitted candidate
        // the second distance is +inf and test 3 is vacuous.
        r.verdict = apply_match_tests(options_.match, nc, best, second, r.mean_distance);
      }
    }
    still_unmatched_.clear();
    for (int q = 0; q < nq; ++q) {
      const int i = unmatched_[static_cast<std::size_t>(q)];
      const MatchResult& r = results_[static_cast<std::size_t>(q)];
      bool ok = r.accepted();
      LinkVerdict why = ok ? LinkVerdict::kLinked : LinkVerdict::kNoCandidates;
      if (ok && k > 1 && options_.look_back_f1 > 0.0 && r.min_distance > options_.look_back_f1) {
        ok = false;  // test 1 with the look-back F1
        why = LinkVerdict::kLookBackF1;
      }
      // Confirmed F1: a distance between F1 (or the look-back F1) and confirm_f1 is accepted
      // when tests 2 and 3 pass and the track's prediction confirms the line (checked below;
      // counted as a test 1 rejection only if that fails).
      bool needs_confirmation = false;
      if (options_.confirm_f1 > 0.0 && r.best >= 0 && r.min_distance <= options_.confirm_f1 &&
          (why == LinkVerdict::kLookBackF1 || r.verdict == MatchVerdict::kFailedTest1)) {
        MatchOptions relaxed = options_.match;
        relaxed.f1 = options_.confirm_f1;
        const int nc = static_cast<int>(slot.num_lines);
        if (apply_match_tests(relaxed, nc, r.min_distance, r.second_distance, r.mean_distance) ==
            MatchVerdict::kAccepted) {
          needs_confirmation = true;
        }
      }
      if (why == LinkVerdict::kLookBackF1 && !needs_confirmation) ++stats_.rejected_test1;
      switch (r.verdict) {
        case MatchVerdict::kFailedTest1:
          if (!needs_confirmation) ++stats_.rejected_test1;
          why = LinkVerdict::kTest1;
          break;
        case MatchVerdict::kFailedTest2:
          ++stats_.rejected_test2;
          why = LinkVerdict::kTest2;
          break;
        case MatchVerdict::kFailedTest3:
          ++stats_.rejected_test3;
          why = LinkVerdict::kTest3;
          break;
        default:
          break;
      }
      const LinkVerdict f1_verdict = why;  // what refuses the link if confirmation fails
      if (needs_confirmation) {
        ok = true;
        why = LinkVerdict::kLinked;
      }
      const std::int64_t id = ok ? slot.track_ids[static_cast<std::size_t>(r.best)] : -1;
      if (ok && options_.mutual) {
        // Reverse direction first (so that the reason does not depend on the order in which
        // lines are processed): the nearest line of the new frame to B_best must be A_i.
        // Computed for the accepted candidate only (n dot products), ties to lowest index.
        int nearest = -1;
        if (restrict) {
          // Among the lines of the new frame admissible for B_best.
          const auto b = slot.descriptors.row(r.best);
          float nearest_sq = std::numeric_limits<float>::infinity();
          for (int a = 0; a < n; ++a) {
            if (!admissible(a, r.best)) continue;
            const float sq = (frame.descriptors.row(a) - b).squaredNorm();
            if (sq < nearest_sq) {
              nearest_sq = sq;
              nearest = a;
            }
          }
        } else if (all_rows) {
          // The whole column of distances to B_best is at hand (row q is line q).
          Eigen::Index idx = 0;
          matcher_.last_distances().col(r.best).minCoeff(&idx);
          nearest = static_cast<int>(idx);
        } else {
          const auto b = slot.descriptors.row(r.best);
          float nearest_sq = std::numeric_limits<float>::infinity();
          for (int a = 0; a < n; ++a) {
            const float sq = (frame.descriptors.row(a) - b).squaredNorm();
            if (sq < nearest_sq) {
              nearest_sq = sq;
              nearest = a;
            }
          }
        }
        if (nearest != i) {
          ++stats_.rejected_mutual;
          ok = false;
          why = LinkVerdict::kMutual;
        } else if (track_claimed(id)) {
          // One line per track and frame: taken by a line matched in a more recent frame.
          ++stats_.rejected_claimed;
          ok = false;
          why = LinkVerdict::kClaimed;
        }
      }
      if (ok && options_.gate.enabled &&
          !gate.admits(slot.bearings[static_cast<std::size_t>(r.best)],
                       frame.lines[static_cast<std::size_t>(i)].bearing)) {
        ++stats_.rejected_gate;
        ok = false;
        why = LinkVerdict::kGate;
      }
      const bool continuity = options_.gate.enabled && options_.continuity_tolerance > 0.0;
      if (ok && (continuity || needs_confirmation)) {
        // One prediction of the track serves both checks; confirmation needs continuity.
        const TrackPrediction p = continuity ? predict_track(k, r.best) : TrackPrediction{};
        if (continuity && !continues_track(p, frame.lines[static_cast<std::size_t>(i)].bearing)) {
          ++stats_.rejected_continuity;
          ok = false;
          why = LinkVerdict::kContinuity;
        } else if (needs_confirmation && !(continuity && confirms_track(p, frame, i))) {
          ++stats_.rejected_test1;
          ok = false;
          why = f1_verdict;
        }
      }
      if (ok && k > 1 && options_.heads_only && observed_since(id, k)) {
        ++stats_.rejected_fork;
        ok = false;
        why = LinkVerdict::kFork;
      }
      if (k == 1) {
        TrackAssignment& a = (*out)[static_cast<std::size_t>(i)];
        a.previous_verdict = why;
        a.previous_candidate = r.best;
        a.previous_distance = r.min_distance;
      }
      if (!ok) {
        still_unmatched_.push_back(i);
        continue;
      }
      TrackAssignment& a = (*out)[static_cast<std::size_t>(i)];
      a.track_id = id;
      a.frames_back = k;
      a.matched_line = r.best;
      a.distance = r.min_distance;
      if (options_.mutual) claimed_.push_back(id);
      if (k == 1) {
        ++stats_.matched_previous;
      } else {
        ++stats_.matched_look_back;
      }
    }
    unmatched_.swap(still_unmatched_);
  }

  // Sec. 9.1: no correspondence in any of the frames looked at: a new track.
  for (int i : unmatched_) {
    TrackAssignment& a = (*out)[static_cast<std::size_t>(i)];
    a.track_id = next_track_id_++;
    ++stats_.new_tracks;
  }
  store_frame(frame, *out);
  ++stats_.frames;
  stats_.lines += n;
}

bool Tracker::observed_since(std::int64_t id, int k) {
  for (int m = 1; m < k; ++m) {
    const Slot& s = slot_back(m);
    const auto end = s.track_ids.begin() + s.num_lines;
    if (std::find(s.track_ids.begin(), end, id) != end) return true;
  }
  return false;
}

Tracker::TrackPrediction Tracker::predict_track(int k, int j) const {
  const Slot& s1 = slot_back(k);
  const double rate = s1.parallax_rates[static_cast<std::size_t>(j)];
  TrackPrediction p;
  // u = bearing + theta is free of the robot's rotation (eq. 16); its change is parallax.
  p.u = s1.bearings[static_cast<std::size_t>(j)] + s1.odometry.theta;
  const double path = odometry_.path_length - s1.odometry.path_length;
  const double d_theta = odometry_.theta - s1.odometry.theta;
  const double d_min = options_.gate.min_feature_distance;
  // Camera swing under rotation (the camera is at most rho_max from the axle), as in the gate.
  const double swing = 2.0 * options_.gate.max_camera_offset * std::abs(std::sin(0.5 * d_theta));
  const double swing_bound = swing < d_min ? std::asin(swing / d_min) : kPi;
  if (options_.continuity_model == TrackerOptions::ContinuityModel::kTrack) {
    const double turn_rate = s1.turn_rates[static_cast<std::size_t>(j)];
    // Translation: the parallax the rate predicts, and what it cannot (curvature), at most the
    // sound bound asin(path / D_min) (which is all there is without a rate).
    const double path_bound = path < d_min ? std::asin(path / d_min) : kPi;
    if (std::isnan(rate)) {
      p.spread += path_bound;
      p.rates_known = path <= 0.005;
    } else {
      p.u += rate * path;
      p.spread += std::min(path_bound, options_.continuity_path_curvature * path * path);
    }
    if (std::isnan(turn_rate)) {
      p.spread += swing_bound;
      p.rates_known = p.rates_known && std::abs(d_theta) <= 0.01;
    } else {
      p.u += turn_rate * d_theta;
      p.spread += std::min(swing_bound, options_.continuity_turn_curvature * d_theta * d_theta);
    }
    return p;
  }
  if (std::isnan(rate)) {  // no recent history: nothing to predict from
    p.spread = kPi;
    p.rates_known = false;
    return p;
  }
  p.u += rate * path;
  p.spread = std::asin(std::min(1.0, swing / d_min));
  return p;
}

bool Tracker::continues_track(const TrackPrediction& p, double bearing) const {
  const double tol = options_.continuity_tolerance + p.spread;
  if (tol >= kPi) return true;
  return std::abs(angle_diff(bearing + odometry_.theta, p.u)) <= tol;
}

bool Tracker::confirms_track(const TrackPrediction& p, const FrameFeatures& frame, int line) const {
  // Only where the model predicts well: rates measured, and what it cannot predict (curvature)
  // no larger than the tolerance itself.
  if (!p.rates_known || p.spread > options_.confirm_tolerance) return false;
  const double tight = options_.confirm_tolerance + p.spread;
  const double wide = options_.continuity_tolerance + p.spread;
  if (tight >= kPi || wide >= kPi) return false;
  if (std::abs(angle_diff(frame.lines[static_cast<std::size_t>(line)].bearing + odometry_.theta,
                          p.u)) > tight) {
    return false;
  }
  // Unambiguous: no other line of the new frame could continue the track.
  for (std::size_t a = 0; a < frame.lines.size(); ++a) {
    if (static_cast<int>(a) == line) continue;
    if (std::abs(angle_diff(frame.lines[a].bearing + odometry_.theta, p.u)) <= wide) return false;
  }
  return true;
}

void Tracker::store_frame(const FrameFeatures& frame, const std::vector<TrackAssignment>& out) {
  const int n = static_cast<int>(frame.lines.size());
  // Track continuity: each line's parallax per metre, from its link when that spans at most 3
  // frames (NaN: unknown). Computed before the slot of frame t - look_back is overwritten.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  rates_.assign(static_cast<std::size_t>(n), kNaN);
  turn_rates_.assign(static_cast<std::size_t>(n), kNaN);
  const bool track_model =
      options_.continuity_model == TrackerOptions::ContinuityModel::kTrack;
  if (track_model && options_.continuity_tolerance > 0.0 && options_.gate.enabled) {
    // Each observation carries its track's rates: measured on its link when that spans at most
    // 3 frames and the motion in between separates them (mostly translation: per metre; mostly
    // rotation on the spot: per radian), otherwise inherited from the observation linked to.
    for (int i = 0; i < n; ++i) {
      const TrackAssignment& a = out[static_cast<std::size_t>(i)];
      if (a.frames_back < 1 || a.matched_line < 0) continue;
      const Slot& s0 = slot_back(a.frames_back);
      const auto j = static_cast<std::size_t>(a.matched_line);
      double rate = s0.parallax_rates[j], turn_rate = s0.turn_rates[j];
      if (a.frames_back <= 3) {
        const double u0 = s0.bearings[j] + s0.odometry.theta;
        const double u1 = frame.lines[static_cast<std::size_t>(i)].bearing + odometry_.theta;
        const double du = angle_diff(u1, u0);
        const double path = odometry_.path_length - s0.odometry.path_length;
        const double d_theta = odometry_.theta - s0.odometry.theta;
        const bool moved = path > 0.01, turned = std::abs(d_theta) > 0.02;
        if (moved && (!turned || !std::isnan(turn_rate))) {
          rate = (du - (turned ? turn_rate * d_theta : 0.0)) / path;
        } else if (turned && (path < 0.005 || !std::isnan(rate))) {
          turn_rate = (du - (std::isnan(rate) ? 0.0 : rate * path)) / d_theta;
        } else if (moved && turned) {
          rate = turn_rate = kNaN;  // both unknown and not separable
        }
      }
      rates_[static_cast<std::size_t>(i)] = rate;
      turn_rates_[static_cast<std::size_t>(i)] = turn_rate;
    }
  } else if (options_.continuity_tolerance > 0.0 && options_.gate.enabled) {
    for (int i = 0; i < n; ++i) {
      const TrackAssignment& a = out[static_cast<std::size_t>(i)];
      if (a.frames_back < 1 || a.frames_back > 3 || a.matched_line < 0) continue;
      const Slot& s0 = slot_back(a.frames_back);
      const double u0 = s0.bearings[static_cast<std::size_t>(a.matched_line)] + s0.odometry.theta;
      const double u1 = frame.lines[static_cast<std::size_t>(i)].bearing + odometry_.theta;
      const double path = odometry_.path_length - s0.odometry.path_length;
      // None known when the robot turned on the spot in between.
      rates_[static_cast<std::size_t>(i)] = path > 0.01 ? angle_diff(u1, u0) / path : 0.0;
    }
  }
  // The slot of frame t replaces that of frame t - look_back, which is no longer needed.
  Slot& slot = ring_[static_cast<std::size_t>(frame_count_ % options_.look_back)];
  const Eigen::Index cols = frame.descriptors.cols();
  if (slot.descriptors.rows() < n || slot.descriptors.cols() != cols) {
    slot.descriptors.resize(line_capacity(std::max<Eigen::Index>(slot.descriptors.rows(), n)),
                            cols);
    slot.bearings.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.polarities.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.parallax_rates.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.turn_rates.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
    slot.track_ids.reserve(static_cast<std::size_t>(slot.descriptors.rows()));
  }
  if (n > 0) slot.descriptors.topRows(n) = frame.descriptors;
  slot.bearings.resize(static_cast<std::size_t>(n));
  slot.polarities.resize(static_cast<std::size_t>(n));
  slot.parallax_rates.assign(rates_.begin(), rates_.end());
  slot.turn_rates.assign(turn_rates_.begin(), turn_rates_.end());
  slot.track_ids.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    slot.bearings[static_cast<std::size_t>(i)] = frame.lines[static_cast<std::size_t>(i)].bearing;
    slot.polarities[static_cast<std::size_t>(i)] =
        frame.lines[static_cast<std::size_t>(i)].polarity;
    slot.track_ids[static_cast<std::size_t>(i)] = out[static_cast<std::size_t>(i)].track_id;
  }
  slot.num_lines = n;
  slot.odometry = odometry_;
  ++frame_count_;
}

}  // namespace omnivert
