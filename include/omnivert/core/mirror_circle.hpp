#pragma once
// The mirror's image: its centre (where all radial lines meet) and the valid annulus
// R_min..R_max between the camera's self-reflection and the mirror rim (Sec. 2, step 1).

#include <Eigen/Core>

namespace omnivert {

struct MirrorCircle {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // pixels, sub-pixel
  double r_min = 0.0;                                // pixels
  double r_max = 0.0;                                // pixels
  double rim_radius = 0.0;  // radius of the detected outer boundary (0 if not detected)
};

}  // namespace omnivert
