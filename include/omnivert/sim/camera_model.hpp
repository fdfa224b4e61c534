#pragma once
// The simulated catadioptric camera: a central camera (unified sphere model, Geyer-Daniilidis
// / Mei) whose mirror axis is vertical, so that every world vertical line is a radial image
// line (Sec. 2).
//
// Model. A viewing direction of camera bearing beta (counter-clockwise from the camera
// x-axis, z up) and elevation el (above the horizontal plane of the camera centre) is drawn
// at radius
//     r(el) = gamma * cos(el) / (xi - sin(el))
// from the mirror centre (cx, cy), at image angle a = bearing_sign * beta:
//     (u, v) = (cx + r cos a, cy + r sin a)            (docs/theory/conventions.md)
// This is the unified model with its optical axis pointing down along the mirror axis
// (z_m = -z), unit-sphere point (cos el cos beta, cos el sin beta, -sin el), projected with
// m = (x_s, y_s) / (z_s + xi) and u = gamma * m + c. The self-reflection of the camera is at
// the image centre (el = -pi/2, r = 0); r grows monotonically with the elevation up to the
// asymptote el = asin(xi). Valid domain: 0 < xi < 1, gamma > 0, el in (-pi/2, asin(xi)).
//
// The valid annulus r_min..r_max (Sec. 2) is the part of the image used by the pipeline; the
// renderer draws the world a little beyond it, the camera's own dark reflection inside
// r_min and the dark mirror rim just outside r_max.

#include <string>

#include <Eigen/Core>

#include "omnivert/core/camera_geometry.hpp"

namespace omnivert::sim {

struct CatadioptricCamera {
  int width = 640;
  int height = 480;
  // Mirror centre in pixels. Deliberately not at the image centre nor on a pixel centre.
  double cx = 321.37;
  double cy = 238.81;
  double xi = 0.9;       // unified model mirror parameter, 0 < xi < 1
  double gamma = 130.0;  // generalised focal length [px]
  double r_min = 60.0;   // valid annulus [px]
  double r_max = 215.0;
  int bearing_sign = 1;  // +1: a = beta; -1: a = -beta (docs/theory/conventions.md)
  // Tilt of the mirror axis from the vertical [deg], leaning towards the camera bearing
  // tilt_direction_deg (core/tilt.hpp, docs/theory/tilt.md). The model above holds in the
  // mirror's own frame; the renderer rotates the viewing directions. 0: upright.
  double tilt_deg = 0.0;
  double tilt_direction_deg = 0.0;

  // Radius [px] of the elevation el [rad]; el must lie in the valid domain.
  double radius_of_elevation(double el) const;
  // Inverse of the above, for r >= 0 (closed form, see camera_model.cpp).
  double elevation_of_radius(double r) const;
  // Pixel of a direction given by camera bearing and elevation [rad].
  Eigen::Vector2d pixel_of(double bearing, double elevation) const;
  // Projects a point given in the camera frame (x along the camera x-axis, z up) to a pixel.
  // Returns false (and leaves px untouched) when the point is at the centre or outside the
  // model's domain (el >= asin(xi)).
  bool project(const Eigen::Vector3d& p_cam, Eigen::Vector2d& px) const;

  // Radius of the mirror's outer boundary as drawn: the world inside, dark outside.
  double rim_radius() const { return r_max + 3.0; }
  // Radius of the camera's own (dark) reflection.
  double self_radius() const { return r_min - 3.0; }

  // The pipeline's view of this camera (what cam0/sensor.yaml holds).
  CameraGeometry geometry() const;
  // Checks the parameters; returns an empty string or what is wrong.
  std::string validate() const;
};

}  // namespace omnivert::sim
