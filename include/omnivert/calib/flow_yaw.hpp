#pragma once

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// The camera's yaw phi + psi as the bearings' flow shows it, without any estimate: while the
// robot drives, each line's bearing moves away from the direction of travel (a camera moving
// at velocity v sees a point at distance d and world direction alpha turn at
// |v| sin(alpha - alpha_v) / d), and that direction is -(phi + psi) in the camera's frame
// (eq. 30 with the camera moving along the robot's heading). Each track's inverse distance is
// fitted for each candidate yaw; the yaw whose fits explain most of the flow is returned. NaN
// when the run has too little translation or flow to tell (fewer than `min_pairs` bearing
// pairs, or less than `min_explained` of the flow's sum of squares explained).
// The window starts at this yaw as well where it is far from the prior's: every start at the
// prior's camera yaw is far off for a camera mounted 80-110 degrees from it //
// (docs/theory/window.md#camera-yaw-from-the-bearings-flow).
double camera_yaw_from_flow(const CalibrationRun& run,
                            double wheel_base,
                            int min_pairs = 20,
                            double min_explained = 0.3);

}  // namespace omnivert::calib
