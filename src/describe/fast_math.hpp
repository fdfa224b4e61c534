#pragma once
// Fast approximations for per-pixel loops.

#include <cmath>

namespace omnivert {

// atan2 with a maximum error of about 1e-5 rad (minimax polynomial for atan on [0, 1] with
// octant reduction), in (-pi, pi]. Used per pixel in the descriptor, where 32 bins of 11.25
// degrees make this error irrelevant.
inline float fast_atan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float mx = ax > ay ? ax : ay;
  const float mn = ax > ay ? ay : ax;
  if (mx == 0.0f) return 0.0f;
  const float z = mn / mx;
  const float z2 = z * z;
  float r =
      z * (0.99997726f +
           z2 * (-0.33262347f +
                 z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f - 0.01172120f * z2)))));
  if (ay > ax) r = 1.57079637f - r;
  if (x < 0) r = 3.14159274f - r;
  if (y < 0) r = -r;
  return r;
}

// fast_atan2 without the early return, so that a loop over an array of gradients vectorises:
// equal to fast_atan2 for every (y, x).
inline float fast_atan2_any(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float mx = ax > ay ? ax : ay;
  const float mn = ax > ay ? ay : ax;
  const float z = mn / (mx > 0.0f ? mx : 1.0f);  // (0, 0): 0 / 1
  const float z2 = z * z;
  float r =
      z * (0.99997726f +
           z2 * (-0.33262347f +
                 z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f - 0.01172120f * z2)))));
  r = ay > ax ? 1.57079637f - r : r;
  r = x < 0 ? 3.14159274f - r : r;
  return y < 0 ? -r : r;
}

}  // namespace omnivert
