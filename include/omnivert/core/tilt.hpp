#pragma once
// A tilted mirror axis (docs/theory/tilt.md). The camera frame C is the mirror's: z along the
// mirror axis, x the camera x-axis. The upright frame V shares the camera centre, has z
// vertical and is the frame whose horizontal angles are the bearings of eq. (16)-(17). The
// mirror axis leans by the angle `tilt` towards the camera bearing `direction`: the axis is
// (sin tilt cos direction, sin tilt sin direction, cos tilt) in V, and
//     R_VC = rotation about k = (-sin direction, cos direction, 0) by tilt.
// With tilt = 0 the two frames are one and every world vertical is a radial image line.

#include <Eigen/Core>

namespace omnivert {

// The rotation taking directions in the camera (mirror) frame C to the upright frame V.
Eigen::Matrix3d tilt_rotation(double tilt, double direction);

// The tilt as a small-angle vector: (tilt cos direction, tilt sin direction) [rad]; the
// estimator's unknowns (smooth through zero tilt, where the direction is undefined).
Eigen::Matrix3d tilt_rotation_of_vector(const Eigen::Vector2d& tilt_vector);

// Unit direction of camera bearing beta and elevation el [rad] (z up).
Eigen::Vector3d unit_direction(double beta, double el);

}  // namespace omnivert
