#include "omnivert/core/camera_geometry.hpp"

#include <cmath>

#include <yaml-cpp/yaml.h>

#include "core/yaml_fields.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {

double CameraGeometry::bearing_of_image_angle(double a) const {
  return wrap_angle(bearing_sign * a);
}

double CameraGeometry::image_angle_of_bearing(double beta) const {
  return wrap_angle(bearing_sign * beta);
}

double CameraGeometry::elevation_of_radius(double r) const {
  // r (xi - sin el) = gamma cos el  <=>  hypot(r, gamma) sin(el + atan2(gamma, r)) = r xi; the
  // branch that is monotonic from el = -pi/2 at r = 0.
  return std::asin(r * *xi / std::hypot(r, *gamma)) - std::atan2(*gamma, r);
}

double CameraGeometry::radius_of_elevation(double el) const {
  return *gamma * std::cos(el) / (*xi - std::sin(el));
}

CameraGeometry load_camera_geometry(const std::string& path) {
  const YAML::Node root = yaml::load_file(path);
  CameraGeometry g;

  const auto res = yaml::optional_numbers(root, "resolution", 2, path);
  if (!res) throw InputError(path, 0, "missing required field 'resolution: [width, height]'");
  for (double v : *res) {
    if (v < 1.0 || v != std::floor(v)) {
      throw InputError(path,
                       yaml::line_of(root["resolution"]),
                       "field 'resolution' must hold two positive whole numbers of pixels");
    }
  }
  g.width = static_cast<int>((*res)[0]);
  g.height = static_cast<int>((*res)[1]);

  if (const auto c = yaml::optional_numbers(root, "center", 2, path)) {
    if ((*c)[0] < 0 || (*c)[1] < 0 || (*c)[0] >= g.width || (*c)[1] >= g.height) {
      throw InputError(path,
                       yaml::line_of(root["center"]),
                       "field 'center' must lie inside the image of the given resolution");
    }
    g.center = Eigen::Vector2d((*c)[0], (*c)[1]);
  }
  g.r_min = yaml::optional_number(root, "r_min", path, /*non_negative=*/true);
  g.r_max = yaml::optional_number(root, "r_max", path, /*non_negative=*/true);
  if (g.r_max && *g.r_max <= 0.0) {
    throw InputError(path, yaml::line_of(root["r_max"]), "field 'r_max' must be positive");
  }
  if (g.r_min && g.r_max && *g.r_min >= *g.r_max) {
    throw InputError(
        path, yaml::line_of(root["r_min"]), "field 'r_min' must be smaller than 'r_max'");
  }
  if (const auto s = yaml::optional_number(root, "bearing_sign", path)) {
    if (*s != 1.0 && *s != -1.0) {
      throw InputError(
          path, yaml::line_of(root["bearing_sign"]), "field 'bearing_sign' must be 1 or -1");
    }
    g.bearing_sign = static_cast<int>(*s);
  }
  g.xi = yaml::optional_number(root, "xi", path);
  g.gamma = yaml::optional_number(root, "gamma", path);
  if (g.xi && !(*g.xi > 0.0 && *g.xi < 1.0)) {
    throw InputError(path, yaml::line_of(root["xi"]), "field 'xi' must lie in (0, 1)");
  }
  if (g.gamma && !(*g.gamma > 0.0)) {
    throw InputError(path, yaml::line_of(root["gamma"]), "field 'gamma' must be positive");
  }
  return g;
}

}  // namespace omnivert
