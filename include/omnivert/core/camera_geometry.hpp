#pragma once
// The image-side geometry of a catadioptric camera with a vertical mirror axis, as read from
// cam0/sensor.yaml: image size, mirror centre, valid annulus R_min..R_max (Sec. 2) and the
// sign that turns an image angle into a camera bearing (docs/theory/conventions.md).
//
// Conventions (docs/theory/conventions.md): pixel (u right, v down); image angle a = atan2(v - cy,
// u - cx); camera bearing beta = bearing_sign * a, wrapped to (-pi, pi].

#include <optional>
#include <string>

#include <Eigen/Core>

namespace omnivert {

// Colour filter array of a raw single-channel image, named by the colours of the top-left 2x2
// block read row by row (RGGB: red at (0, 0), blue at (1, 1)).
enum class BayerPattern { kNone, kRGGB, kBGGR, kGRBG, kGBRG };

// How the stored pixels are turned into the 8-bit grey image every stage works on
// (docs/dataset-format.md#pixel-format).
struct PixelFormat {
  // A raw Bayer image is demosaiced before the grey conversion; kNone: the image is grey or
  // colour as stored.
  BayerPattern bayer = BayerPattern::kNone;
  // Significant bits of a 16-bit image whose values are not scaled to the full 16-bit range
  // (a 12-bit camera writing 0..4095): 9..16. 0: the full range, 0..65535.
  int bit_depth = 0;
};

// "RGGB", "BGGR", "GRBG", "GBRG" or "none"; nullopt for anything else (case-insensitive).
std::optional<BayerPattern> parse_bayer_pattern(const std::string& name);
const char* bayer_pattern_name(BayerPattern pattern);

struct CameraGeometry {
  int width = 0;
  int height = 0;
  // Mirror centre in pixels; absent: estimated on every frame.
  std::optional<Eigen::Vector2d> center;
  // Valid annulus in pixels; absent: estimated from the mirror rim.
  std::optional<double> r_min;
  std::optional<double> r_max;
  // +1: beta = a; -1: beta = -a (mirror-flipped image).
  int bearing_sign = 1;
  // Bayer pattern and bit depth of the stored images (fields 'bayer' and 'bit_depth').
  PixelFormat pixel_format;
  // Image mask (`mask:`, a path relative to the yaml's folder, stored resolved): a one-channel
  // image of the camera's resolution whose non-zero pixels are usable; every stage ignores the
  // others (robot, struts, cables). Absent: every pixel is usable. Read by the image stage
  // (read_mask): core has no image reader.
  std::optional<std::string> mask;
  // Unified-model intrinsics (model: unified, docs/dataset-format.md): the projection
  // r(el) = gamma cos(el) / (xi - sin(el)); absent when the file does not give them. Only the
  // tilt estimate needs them (docs/theory/tilt.md).
  std::optional<double> xi;
  std::optional<double> gamma;

  bool has_projection() const { return xi.has_value() && gamma.has_value(); }
  // Elevation [rad] of the viewing direction drawn at radius r [px] from the centre; needs
  // has_projection() (the inverse of r(el), docs/theory/tilt.md#projection).
  double elevation_of_radius(double r) const;
  // Radius [px] of elevation el [rad], r(el) above; needs has_projection().
  double radius_of_elevation(double el) const;

  // Camera bearing of an image angle (docs/theory/conventions.md).
  double bearing_of_image_angle(double a) const;
  // Image angle of a camera bearing (inverse of the above).
  double image_angle_of_bearing(double beta) const;
};

// Reads the fields above from a sensor.yaml. Fields other than these are ignored (the
// simulator adds its intrinsics). Throws InputError naming the file, the line and the field
// for: a missing file, YAML that does not parse, a missing or non-numeric resolution,
// negative or non-numeric values, r_min >= r_max, bearing_sign other than +-1, an unknown
// bayer pattern, a bit_depth outside 9..16, a mask field that is not a file name or names a
// file that does not exist.
CameraGeometry load_camera_geometry(const std::string& path);

}  // namespace omnivert
