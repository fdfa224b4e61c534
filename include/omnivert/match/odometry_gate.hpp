#pragma once
// A gate on the bearing change of a static world vertical line between two frames, from the
// wheel travel alone: no extrinsics needed (docs/theory/matching.md#odometry-gate).
//
// Bearing model, eqs. (16)-(17) (docs/theory/conventions.md):
//   beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + phi + psi).
// Between two frames the camera yaw theta_R + phi + psi changes by exactly the robot rotation
// d_theta (the camera is rigid on the robot), whatever phi and psi are. The world direction
// from the camera centre C to the line changes by the angle that the displacement C1 -> C2
// subtends at the line. With s = |C1 C2| and D_min a lower bound on the distance of the line
// from the camera at both frames, that angle is at most asin(s / D_min) when s < D_min (law of
// sines: sin(angle at f) = s sin(angle at C1) / |f C2|, and the angle at f is acute because it
// faces a side that is not the longest). Hence
//   |wrap(beta_2 - beta_1 + d_theta)| <= asin(s / D_min)
// with s <= L + 2 rho_max |sin(d_theta / 2)|, where L is the path length of the robot's
// reference point (the wheel-axle midpoint, sum of |d_rho|) and the second term the motion of
// a camera at distance <= rho_max from it caused by the rotation. When s >= D_min nothing is
// known and the gate passes everything.
//
// Tolerances: `bearing_tolerance` for the bearing noise of two detections, and
// `slip_fraction * W / e` for the rotation error of the odometry, W being the summed travel
// |d_R| + |d_L| of both wheels (Chong-Kleeman, eq. 31: the error of each wheel grows with its
// travel; the rotation error is the difference of the two over e).

#include <string>

namespace omnivert {

// Wheel travel since the previous frame (metres), as in eq. (15): d_rho = (d_R + d_L)/2,
// d_theta = (d_R - d_L)/e.
struct WheelIncrement {
  double d_right = 0.0;
  double d_left = 0.0;
};

// The increment between two frames from the cumulative wheel travel at their timestamps (as
// the dataset reader gives it, wheel0/data.csv: `left [m], right [m]`, cumulative).
inline WheelIncrement increment_between(double left_before,
                                        double right_before,
                                        double left_after,
                                        double right_after) {
  return WheelIncrement{right_after - right_before, left_after - left_before};
}

struct OdometryGateOptions {
  bool enabled = false;
  double wheel_base = 0.0;            // e, metres (required when enabled)
  double min_feature_distance = 0.5;  // D_min, metres: lines nearer than this may be rejected
  double max_camera_offset = 0.3;     // rho_max, metres: bound on rho (camera to axle midpoint)
  double bearing_tolerance = 0.035;   // radians (2 degrees): detection noise of both bearings
  double slip_fraction = 0.05;        // rotation error per unit wheel travel (relative)

  bool IsValid(std::string* error) const;
};

// Odometry accumulated from the start of a run; differences of two of these describe the
// motion between two frames in O(1).
struct OdometryAccumulator {
  double theta = 0.0;         // sum of d_theta (radians), not wrapped
  double path_length = 0.0;   // sum of |d_rho| (metres)
  double wheel_travel = 0.0;  // sum of |d_R| + |d_L| (metres)
  double x = 0.0, y = 0.0;    // the axle midpoint's position (metres), eq. (14)

  void add(const WheelIncrement& inc, double wheel_base);
};

// The gate for one pair of frames.
struct BearingGate {
  double predicted_change = 0.0;  // -d_theta: the exact rotation part
  double max_deviation = 0.0;     // bound on |wrap(beta_2 - beta_1 - predicted_change)|
  bool informative = false;       // false when the bound is pi (translation too large)

  bool admits(double bearing_before, double bearing_after) const;
};

// Gate for the motion between `before` and `after` (accumulators at the two frames).
BearingGate make_bearing_gate(const OdometryGateOptions& options,
                              const OdometryAccumulator& before,
                              const OdometryAccumulator& after);

}  // namespace omnivert
