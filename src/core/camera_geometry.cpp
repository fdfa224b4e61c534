#include "omnivert/core/camera_geometry.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>

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

std::optional<BayerPattern> parse_bayer_pattern(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::toupper(c); });
  if (n == "NONE") return BayerPattern::kNone;
  if (n == "RGGB") return BayerPattern::kRGGB;
  if (n == "BGGR") return BayerPattern::kBGGR;
  if (n == "GRBG") return BayerPattern::kGRBG;
  if (n == "GBRG") return BayerPattern::kGBRG;
  return std::nullopt;
}

const char* bayer_pattern_name(BayerPattern pattern) {
  switch (pattern) {
    case BayerPattern::kRGGB:
      return "RGGB";
    case BayerPattern::kBGGR:
      return "BGGR";
    case BayerPattern::kGRBG:
      return "GRBG";
    case BayerPattern::kGBRG:
      return "GBRG";
    case BayerPattern::kNone:
      break;
  }
  return "none";
}

namespace {

PixelFormat load_pixel_format(const YAML::Node& root, const std::string& path) {
  PixelFormat f;
  if (const auto b = yaml::optional_string(root, "bayer", path)) {
    const auto p = parse_bayer_pattern(*b);
    if (!p) {
      throw InputError(path,
                       yaml::line_of(root["bayer"]),
                       "field 'bayer' is '" + *b + "'; expected RGGB, BGGR, GRBG, GBRG or none");
    }
    f.bayer = *p;
  }
  if (const auto d = yaml::optional_number(root, "bit_depth", path)) {
    if (*d != std::floor(*d) || *d < 9 || *d > 16) {
      throw InputError(path,
                       yaml::line_of(root["bit_depth"]),
                       "field 'bit_depth' must be a whole number of bits from 9 to 16 (the "
                       "significant bits of a 16-bit image)");
    }
    f.bit_depth = static_cast<int>(*d);
  }
  return f;
}

}  // namespace

double CameraGeometry::elevation_of_radius(double r) const {
  // r (xi - sin el) = gamma cos el  <=>  hypot(r, gamma) sin(el + atan2(gamma, r)) = r xi; the
  // branch that is monotonic from el = -pi/2 at r = 0.
  return std::asin(r * *xi / std::hypot(r, *gamma)) - std::atan2(*gamma, r);
}

double CameraGeometry::radius_of_elevation(double el) const {
  return *gamma * std::cos(el) / (*xi - std::sin(el));
}

namespace {
constexpr double kMaxImageSide = 100000.0;  // pixels per side of sensor.yaml's resolution
}  // namespace

CameraGeometry load_camera_geometry(const std::string& path) {
  const YAML::Node root = yaml::load_file(path);
  CameraGeometry g;

  const auto res = yaml::optional_numbers(root, "resolution", 2, path);
  if (!res) throw InputError(path, 0, "missing required field 'resolution: [width, height]'");
  for (double v : *res) {
    // The bound keeps the int conversion below defined (a fuzzed file gave 5.6e44).
    if (v < 1.0 || v > kMaxImageSide || v != std::floor(v)) {
      throw InputError(path,
                       yaml::line_of(root["resolution"]),
                       "field 'resolution' must hold two whole numbers of pixels, 1 to " +
                           std::to_string(static_cast<int>(kMaxImageSide)));
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
  g.pixel_format = load_pixel_format(root, path);
  if (const auto m = yaml::optional_string(root, "mask", path)) {
    namespace fs = std::filesystem;
    const int line = yaml::line_of(root["mask"]);
    if (m->empty()) throw InputError(path, line, "field 'mask' must name an image file");
    fs::path p(*m);
    if (p.is_relative()) p = fs::path(path).parent_path() / p;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) {
      throw InputError(path,
                       line,
                       "field 'mask': file '" + *m + "' not found (looked for " + p.string() +
                           "; the path is relative to the folder of this file)");
    }
    g.mask = p.string();
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
