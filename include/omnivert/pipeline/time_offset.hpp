#pragma once
// The camera-odometry time offset, estimated from the data (docs/calibration.md#time-offset).
//
// A static line's bearing changes by -d_theta when the robot turns by d_theta, whatever the
// extrinsics (eq. 16-17: beta = atan2(...) - theta_R - phi - psi), plus a parallax that
// grows with the camera's travel: for line j between images i-1 and i, to first order,
//
//     -d_beta_j(i) = k_j d_theta(i) + c_j d_rho(i)
//
// with d_theta, d_rho the robot's turn and travel over the pair (eq. 15) and k_j, c_j the
// line's own coefficients (k_j = 1 + the swing of a camera off the axle, c_j its parallax per
// metre), nearly constant over a second. The wheels give d_theta, d_rho between any two
// instants; with the image stamps late by S they are taken between t_{i-1} - S and t_i - S.
// For three consecutive pairs (i-1, i, i+1) the line's three equations in (k_j, c_j) leave one
// residual e_j(i, S) = |b_j - A (A^T A)^-1 A^T b_j|, with b_j the line's three turns and A
// the wheels' columns (d_theta, d_rho over the three pairs): zero at the true S, whatever the
// line's distance, and growing with the error of S wherever the motion changes (a turn or a
// straight starting or ending inside the pairs). Per triple the median over its lines (a line
// that changed line is left out so), e(i, S), and the cost J(S) = sum_i e(i, S)^2 on a grid of
// S, each triple weighted by its modelled variance sigma_i^2 = trace(P Sigma P) (P the
// projection away from A; Sigma the wheels' d_theta noise, eq. 31, common to every line, and
// the bearings'), refined by the parabola through the grid minimum and its neighbours. Its
// sigma is the largest of three: the model's, sigma_S^2 = max(s^2, 1) / a, with
// J(S) ~ J_min + a (S - S*)^2 and s^2 = J_min / (n - 1); the sandwich's,
// sum_{|i-k|<=3} g_i g_k / J''^2 (g_i the slope of triple i's term at S*, over
// +-sigma_step_s), which counts once the noise that overlapping
// triples share and takes the residuals as they are: the wheels' noise in the triples where
// the motion changes limits it (0.17 degree per image pair on the simulator: about 10 ms for
// one turn starting); and the delete-a-block jackknife's (blocks of four triples left out in
// turn), which alone sees how many changes of motion carry S: with one, leaving it out leaves J
// without a minimum, and the sigma is hundreds of ms. Only those triples carry S: a run
// without turns (or starts and stops) leaves it undetermined.

#include <cstdint>
#include <string>
#include <vector>

#include "omnivert/dataset/dataset.hpp"
#include "omnivert/match/tracks_io.hpp"

namespace omnivert::pipeline {

struct TimeOffsetOptions {
  double max_offset_s = 0.5;  // S is searched in [-max, max] [s]
  double step_s = 0.001;      // grid step [s]
  int min_common_tracks = 3;  // a triple is used when at least this many lines span it
  int min_pairs = 10;         // fewer usable triples: not determined
  // Not determined when the sigma exceeds this [s] (too few turns starting or ending).
  double max_sigma_s = 0.05;
  // Not determined either when J's median over the grid is less than this above its minimum
  // (in units of the modelled variance): the wheels' noise alone makes J wiggle with S, a
  // minimum that stands out from the wiggles needs a change of motion.
  double min_rise = 25.0;
  // The sandwich sigma's step [s]: the slopes and the curvature of J over +-this (J is a sum of
  // medians, not smooth at the grid's step); 0: the model's sigma alone.
  double sigma_step_s = 0.005;
  // The delete-a-block jackknife's sigma, blocks of this many consecutive triples (four: a
  // triple shares images with the three after it); the sigma reported is the largest of the
  // model's, the sandwich's and the jackknife's. 0: no jackknife.
  int jackknife_block = 4;
  // Threads that evaluate J over the grid (0: every core). Each grid point's sum is taken by
  // one thread in the triples' order, so the estimate is the same for every count.
  int threads = 0;
  // An estimate is applied when |S| exceeds `significance` sigmas and `min_applied_s`: a
  // synchronised recording keeps its stamps (and its results) unchanged.
  double significance = 3.0;
  double min_applied_s = 0.02;
  // Whether an offset with this sigma is applied: |offset| above `significance` sigmas and
  // at least `min_applied_s`.
  bool significant(double offset_s, double sigma_s) const;

  // True when every field is usable; otherwise false with the reason in *why (may be null).
  bool IsValid(std::string* why) const;
};

struct TimeOffsetEstimate {
  bool determined = false;
  double offset_s = 0.0;  // S: positive when the image stamps are late [s]
  double sigma_s = 0.0;
  int pairs = 0;                // triples of image pairs used
  double residual_scale = 0.0;  // s: the residuals' RMS in units of their modelled sigma
  std::string why;              // why not determined
  // Refined with the extrinsics (calib::RefinementOptions::estimate_time_offset): offset_s and
  // sigma_s are then the refinement's (the offset applied before tracking plus its
  // correction), and the estimate from the tracks alone is kept here.
  bool refined = false;
  double tracks_offset_s = 0.0, tracks_sigma_s = 0.0;
  // When the refinement's correction of the offset the images were tracked with was
  // significant, its estimate (retracked_s) was applied, the images tracked again and the run
  // calibrated again, once (offset_s and sigma_s are then the second refinement's);
  // tracks_applied: whether the tracks' estimate had been applied before.
  bool retracked = false;
  double retracked_s = 0.0;
  bool tracks_applied = false;
  // Whether the estimate is significant (TimeOffsetOptions::significance, min_applied_s).
  bool significant(const TimeOffsetOptions& o) const;
};

// The estimate from plain arrays: image times [s] (increasing); per image i >= 1 the turn of
// each line seen in images i-1 and i, -wrap(beta(i) - beta(i-1)) [rad], by track id (index 0
// unused); the wheels' samples: times [s] (increasing), heading theta_w and distance rho_w
// (eq. 15: (d_R - d_L) / e and (d_R + d_L) / 2, cumulative) [rad, m].
struct TimeOffsetInput {
  std::vector<double> image_t;
  std::vector<std::vector<std::pair<std::int64_t, double>>> turns;  // sorted by track id
  std::vector<double> wheel_t, wheel_heading, wheel_distance;
  double wheel_base = 0.4;             // e [m]
  double odometry_k = 1e-5;            // Chong-Kleeman K [m], eq. (31)
  double bearing_sigma = 4.363323e-4;  // [rad] (0.025 degree)
};
TimeOffsetEstimate estimate_time_offset(const TimeOffsetInput& input,
                                        const TimeOffsetOptions& options = {});

// The estimate for a dataset (its raw image stamps) and its tracks (tracks.csv rows), with the
// noise model of the calibration (Chong-Kleeman K [m], bearing sigma [rad]). Not determined
// without a wheel base.
TimeOffsetEstimate estimate_time_offset(const dataset::Dataset& data,
                                        const std::vector<TrackRow>& rows,
                                        double odometry_k,
                                        double bearing_sigma,
                                        const TimeOffsetOptions& options = {});

// One line for the terminal and the report, e.g. "time offset: image stamps late by 41.2 +-
// 0.8 ms (from 92 image pairs); applied" (or "not applied (applied above 3 sigma and 20 ms)");
// refined: "... late by 41.9 +- 2.1 ms (refined with the extrinsics; from the tracks 41.2 +-
// 0.8 ms over 92 image pairs, applied before tracking)".
std::string time_offset_line(const TimeOffsetEstimate& e,
                             bool given,
                             bool applied,
                             const TimeOffsetOptions& options = {});

}  // namespace omnivert::pipeline
