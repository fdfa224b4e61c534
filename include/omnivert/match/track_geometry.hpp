#pragma once
// The geometry a tracker can know without the extrinsics
// (docs/theory/matching.md#triangulated-prediction): the camera's yaw relative to the robot's
// forward direction, from the sign of the parallax of the lines it tracks, and the position of a
// line from two of its bearings and the wheels' travel in between.
//
// Bearing model, eqs. (16)-(17): beta = atan2(y_f - y_C, x_f - x_C) - (theta_R + yaw), with
// yaw = phi + psi the camera's yaw on the robot. Between two frames of straight travel along
// the robot's heading theta, the world direction phi_w = beta + theta_R + yaw of a line turns
// away from the direction of travel: d phi_w / ds = sin(phi_w - theta) / D (D: the line's
// distance), so sign(d beta) = sign(sin(beta + yaw)) whatever D is. Each such pair of bearings
// confines yaw to a half circle; the estimate is the middle of the arc that most pairs agree on.
#include <array>
#include <cmath>

namespace omnivert {

class CameraYawVotes {
 public:
  static constexpr int kBins = 720;  // half a degree each
  // One pair of bearings of a line during straight travel: `bearing` (radians, the camera's,
  // at the middle of the travel) and `change` (radians, the change of its bearing plus the
  // robot's rotation). Pairs whose change is within `min_change` of zero say nothing and are
  // not counted.
  void add(double bearing, double change, double min_change = 0.002);
  // The yaw (radians, in (-pi, pi]) most pairs agree on, or NaN until `min_pairs` pairs were
  // counted, or when the pairs that agree best span more than `max_spread` (radians).
  double estimate(int min_pairs = 200, double max_spread = 0.7) const;
  int pairs() const { return pairs_; }

 private:
  // Difference array of the votes: votes over bins [a, b) are +1 at a, -1 at b.
  std::array<int, kBins + 1> diff_{};
  int pairs_ = 0;
};

// The point where the ray from (x0, y0) with direction angle `dir0` meets the ray from (x1, y1)
// with direction `dir1` (world frame, radians); false when the rays are closer to parallel than
// `min_angle` or meet behind either origin.
bool intersect_rays(double x0,
                    double y0,
                    double dir0,
                    double x1,
                    double y1,
                    double dir1,
                    double min_angle,
                    double* x,
                    double* y);

}  // namespace omnivert
