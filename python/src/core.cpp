// Bindings of the core and image stages: images between numpy and OpenCV, the camera
// geometry of cam0/sensor.yaml (core/camera_geometry.hpp) and its estimation from frames
// (extract/camera_estimate.hpp).

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/extract/camera_estimate.hpp"
#include "omnivert/image/grey.hpp"
#include "omnivert/image/image_io.hpp"

namespace omnivert::python {

namespace {

// OpenCV depth of a numpy dtype; -1 when not supported.
int cv_depth(const py::dtype& d) {
  if (d.kind() == 'u' && d.itemsize() == 1) return CV_8U;
  if (d.kind() == 'u' && d.itemsize() == 2) return CV_16U;
  if (d.kind() == 'f' && d.itemsize() == 4) return CV_32F;
  return -1;
}

// Whether a numpy image can be used by a cv::Mat header as it is: native byte order,
// contiguous pixels and channels, rows at a multiple of the element size.
bool viewable(const py::array& a, int channels) {
  const auto item = static_cast<py::ssize_t>(a.itemsize());
  const std::string order = py::str(a.dtype().attr("byteorder"));
  if (order == ">") return false;
  if (a.ndim() == 3 && a.strides(2) != item) return false;
  if (a.strides(1) != item * channels) return false;
  return a.strides(0) >= a.strides(1) * a.shape(1) && a.strides(0) % item == 0;
}

}  // namespace

cv::Mat image_view(const py::handle& obj, py::object* keep, const std::string& what) {
  if (!py::isinstance<py::array>(obj))
    throw InputError(what + ": expected a numpy array, got " +
                     std::string(py::str(py::type::of(obj).attr("__name__"))));
  auto a = py::reinterpret_borrow<py::array>(obj);
  const int depth = cv_depth(a.dtype());
  if (depth < 0)
    throw InputError(what + ": pixels of type " + std::string(py::str(a.dtype())) +
                     " are not supported (uint8, uint16 or float32 in 0..1)");
  if (a.ndim() != 2 && a.ndim() != 3)
    throw InputError(what + ": expected shape (height, width) or (height, width, channels), got " +
                     std::to_string(a.ndim()) + " dimensions");
  const int channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
  if (channels != 1 && channels != 3 && channels != 4)
    throw InputError(what + ": " + std::to_string(channels) +
                     " channels; expected 1 (grey), 3 (BGR) or 4 (BGRA)");
  if (a.shape(0) == 0 || a.shape(1) == 0) throw InputError(what + ": the image is empty");
  if (!viewable(a, channels))
    a = py::module_::import("numpy").attr("ascontiguousarray")(a,
                                                               a.dtype().attr("newbyteorder")("="));
  *keep = a;
  return cv::Mat(static_cast<int>(a.shape(0)),
                 static_cast<int>(a.shape(1)),
                 CV_MAKETYPE(depth, channels),
                 const_cast<void*>(a.data()),
                 static_cast<std::size_t>(a.strides(0)));
}

py::array to_numpy(cv::Mat image) {
  py::dtype dtype;
  switch (image.depth()) {
    case CV_8U:
      dtype = py::dtype::of<std::uint8_t>();
      break;
    case CV_16U:
      dtype = py::dtype::of<std::uint16_t>();
      break;
    case CV_32F:
      dtype = py::dtype::of<float>();
      break;
    default:
      image.convertTo(image, CV_32F);
      dtype = py::dtype::of<float>();
  }
  auto* owner = new cv::Mat(std::move(image));
  py::capsule base(owner, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto step = static_cast<py::ssize_t>(owner->step[0]);
  const auto elem = static_cast<py::ssize_t>(owner->elemSize());
  const auto elem1 = static_cast<py::ssize_t>(owner->elemSize1());
  if (owner->channels() == 1)
    return py::array(dtype, {owner->rows, owner->cols}, {step, elem}, owner->data, base);
  return py::array(
      dtype, {owner->rows, owner->cols, owner->channels()}, {step, elem, elem1}, owner->data, base);
}

namespace {

// CameraGeometry and load_camera_geometry (cam0/sensor.yaml).
void bind_geometry(py::module_& m) {
  py::class_<CameraGeometry>(m,
                             "CameraGeometry",
                             "The image-side geometry of cam0/sensor.yaml: size, mirror centre, "
                             "valid annulus, bearing sign, pixel format, mask, unified-model xi "
                             "and gamma (docs/dataset-format.md).")
      .def(py::init([](int width,
                       int height,
                       std::optional<Eigen::Vector2d> center,
                       std::optional<double> r_min,
                       std::optional<double> r_max,
                       int bearing_sign,
                       std::optional<std::string> mask,
                       std::optional<double> xi,
                       std::optional<double> gamma) {
             CameraGeometry g;
             g.width = width;
             g.height = height;
             g.center = center;
             g.r_min = r_min;
             g.r_max = r_max;
             g.bearing_sign = bearing_sign;
             g.mask = mask;
             g.xi = xi;
             g.gamma = gamma;
             return g;
           }),
           py::arg("width") = 0,
           py::arg("height") = 0,
           py::arg("center") = py::none(),
           py::arg("r_min") = py::none(),
           py::arg("r_max") = py::none(),
           py::arg("bearing_sign") = 1,
           py::arg("mask") = py::none(),
           py::arg("xi") = py::none(),
           py::arg("gamma") = py::none())
      .def_readwrite("width", &CameraGeometry::width)
      .def_readwrite("height", &CameraGeometry::height)
      .def_readwrite("center", &CameraGeometry::center, "mirror centre (cx, cy) [px] or None")
      .def_readwrite("r_min", &CameraGeometry::r_min)
      .def_readwrite("r_max", &CameraGeometry::r_max)
      .def_readwrite("bearing_sign", &CameraGeometry::bearing_sign)
      .def_readwrite("mask", &CameraGeometry::mask)
      .def_readwrite("xi", &CameraGeometry::xi)
      .def_readwrite("gamma", &CameraGeometry::gamma)
      .def_property(
          "bayer",
          [](const CameraGeometry& g) { return bayer_pattern_name(g.pixel_format.bayer); },
          [](CameraGeometry& g, const std::string& name) {
            const auto p = parse_bayer_pattern(name);
            if (!p) throw InputError("bayer " + name + ": expected RGGB, BGGR, GRBG, GBRG or none");
            g.pixel_format.bayer = *p;
          })
      .def_property(
          "bit_depth",
          [](const CameraGeometry& g) { return g.pixel_format.bit_depth; },
          [](CameraGeometry& g, int bits) { g.pixel_format.bit_depth = bits; })
      .def("bearing_of_image_angle", &CameraGeometry::bearing_of_image_angle, py::arg("a"))
      .def("image_angle_of_bearing", &CameraGeometry::image_angle_of_bearing, py::arg("beta"))
      .def("__repr__", [](const CameraGeometry& g) {
        std::string s = "CameraGeometry(width=" + std::to_string(g.width) +
                        ", height=" + std::to_string(g.height);
        if (g.center)
          s += ", center=(" + std::to_string(g.center->x()) + ", " + std::to_string(g.center->y()) +
               ")";
        if (g.r_min && g.r_max)
          s += ", r_min=" + std::to_string(*g.r_min) + ", r_max=" + std::to_string(*g.r_max);
        return s + ", bearing_sign=" + std::to_string(g.bearing_sign) + ")";
      });
  m.def("load_camera_geometry",
        &load_camera_geometry,
        py::arg("path"),
        "Reads cam0/sensor.yaml; InputError names the file, line and field of a bad value.");
}

// Images: read, write, grey.
void bind_images(py::module_& m) {
  m.def(
      "read_image",
      [](const std::string& path) { return to_numpy(read_image(path)); },
      py::arg("path"),
      "An image file as stored (any depth; colour in OpenCV's BGR order) as a numpy array.");
  m.def(
      "write_image",
      [](const std::string& path, const py::handle& image) {
        py::object keep;
        write_image_atomic(path, image_view(image, &keep));
      },
      py::arg("path"),
      py::arg("image"),
      "Writes a numpy image (format from the extension), under a temporary name then renamed.");
  m.def(
      "to_grey",
      [](const py::handle& image, const CameraGeometry* geometry) {
        py::object keep;
        const cv::Mat view = image_view(image, &keep);
        cv::Mat grey;
        std::string why;
        if (!to_grey8(view, geometry ? geometry->pixel_format : PixelFormat{}, grey, &why))
          throw InputError("image: " + why);
        if (grey.data == view.data) grey = grey.clone();
        return to_numpy(grey);
      },
      py::arg("image"),
      py::arg("geometry") = nullptr,
      "The 8-bit grey image every stage works on (BT.601 luma of BGR; 16 bits scaled by the "
      "camera's bit_depth; a Bayer mosaic demosaiced).");
}

// The camera estimate of `omnivert camera`.
void bind_camera_estimate(py::module_& m) {
  py::class_<CameraEstimate>(m,
                             "CameraEstimate",
                             "A camera's mirror centre, rim, annulus and proposed mask from many "
                             "frames (what `omnivert camera` writes into cam0/sensor.yaml).")
      .def_readonly("width", &CameraEstimate::width)
      .def_readonly("height", &CameraEstimate::height)
      .def_property_readonly(
          "center", [](const CameraEstimate& e) { return Eigen::Vector2d(e.circle.center); })
      .def_property_readonly("r_min", [](const CameraEstimate& e) { return e.circle.r_min; })
      .def_property_readonly("r_max", [](const CameraEstimate& e) { return e.circle.r_max; })
      .def_property_readonly("rim_radius",
                             [](const CameraEstimate& e) { return e.circle.rim_radius; })
      .def_readonly("used_frames", &CameraEstimate::used_frames)
      .def_readonly("spread_px", &CameraEstimate::spread_px)
      .def_readonly("rim_rms_px", &CameraEstimate::rim_rms_px)
      .def_readonly("rim_points", &CameraEstimate::rim_points)
      .def_property_readonly("mask",
                             [](const CameraEstimate& e) -> py::object {
                               if (e.mask.empty()) return py::none();
                               return to_numpy(e.mask.clone());
                             })
      .def_readonly("masked_fraction", &CameraEstimate::masked_fraction)
      .def_readonly("mask_note", &CameraEstimate::mask_note)
      .def(
          "sensor_yaml",
          [](const CameraEstimate& e, const std::string& mask_file, const std::string& provenance) {
            return camera_sensor_yaml(e, mask_file, provenance);
          },
          py::arg("mask_file") = "",
          py::arg("provenance") = "omnivert (Python)",
          "cam0/sensor.yaml text for this estimate.");
  m.def(
      "estimate_camera",
      [](const py::list& frames) {
        std::vector<cv::Mat> grey;
        for (std::size_t i = 0; i < frames.size(); ++i) {
          py::object keep;
          const cv::Mat view = image_view(frames[i], &keep, "frame " + std::to_string(i));
          cv::Mat g;
          std::string why;
          if (!to_grey8(view, PixelFormat{}, g, &why))
            throw InputError("frame " + std::to_string(i) + ": " + why);
          grey.push_back(g.data == view.data ? g.clone() : g);
        }
        py::gil_scoped_release release;
        return estimate_camera(grey);
      },
      py::arg("frames"),
      "The camera from a list of frames of one size (numpy images); InputError when no frame "
      "shows a mirror rim.");
}

}  // namespace

void bind_core(py::module_& m) {
  bind_geometry(m);
  bind_images(m);
  bind_camera_estimate(m);
}

}  // namespace omnivert::python
