// Track continuity of the tracker (TrackerOptions::continuity_tolerance, continuity_model,
// confirm_f1; docs/theory/matching.md): the prediction of a track's bearing in the new frame,
// the checks against it, and the rates each observation carries.
#include <algorithm>
#include <cmath>
#include <limits>

#include "omnivert/core/angles.hpp"
#include "omnivert/match/tracker.hpp"

namespace omnivert {

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
    if (predict_from_position(s1, j, &p)) return p;
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

void Tracker::measure_track_rates(const FrameFeatures& frame,
                                  const std::vector<TrackAssignment>& out) {
  const int n = static_cast<int>(frame.lines.size());
  // Track continuity: each line's parallax per metre, from its link when that spans at most 3
  // frames (NaN: unknown). Computed before the slot of frame t - look_back is overwritten.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  rates_.assign(static_cast<std::size_t>(n), kNaN);
  turn_rates_.assign(static_cast<std::size_t>(n), kNaN);
  const bool track_model = options_.continuity_model == TrackerOptions::ContinuityModel::kTrack;
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
}

}  // namespace omnivert
