#pragma once
// Shared pieces of the Python module (docs/python.md): numpy <-> OpenCV images, the keyword
// option tables, and the registration function of each stage's bindings. The module uses the
// public API only (include/omnivert/...).

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <opencv2/core.hpp>

#include "omnivert/core/angles.hpp"

namespace omnivert::python {

namespace py = pybind11;

// --- images -------------------------------------------------------------------------------

// A cv::Mat header over a numpy image (no copy): uint8, uint16 or float32, shape (h, w) or
// (h, w, c) with c in {1, 3, 4} (colour in OpenCV's BGR order). Rows may be strided (a slice
// of a larger image); pixels and channels must be contiguous, else the array is copied once
// (np.ascontiguousarray). `keep` holds the array the header points into; keep it alive while
// the header is used. Throws InputError naming `what` for any other array.
cv::Mat image_view(const py::handle& array, py::object* keep, const std::string& what = "image");

// A numpy array over a cv::Mat's pixels (no copy: the array owns a reference to them).
py::array to_numpy(cv::Mat image);

// --- keyword options ----------------------------------------------------------------------

// One keyword option of a Python call, bound to a field of the options struct O.
template <class O>
struct Option {
  std::string name;
  std::string doc;
  std::function<py::object(O&)> get;
  std::function<void(O&, const py::handle&)> set;
};
template <class O>
using OptionTable = std::vector<Option<O>>;

// An option bound to the field `access(o)` returns, converted as T.
template <class T, class O, class Access>
Option<O> field(std::string name, std::string doc, Access access) {
  return {std::move(name),
          std::move(doc),
          [access](O& o) { return py::cast(T(access(o))); },
          [access](O& o, const py::handle& v) { access(o) = v.cast<T>(); }};
}
// The same for a field in radians given in degrees.
template <class O, class Access>
Option<O> degrees(std::string name, std::string doc, Access access) {
  return {std::move(name),
          std::move(doc),
          [access](O& o) { return py::cast(rad2deg(access(o))); },
          [access](O& o, const py::handle& v) { access(o) = deg2rad(v.cast<double>()); }};
}

// Sets the options named in `kwargs` that `table` knows, removing them from `kwargs`. A value
// of the wrong type raises TypeError naming the call and the option.
template <class O>
void apply_options(const OptionTable<O>& table, O& o, py::dict& kwargs, const char* call) {
  for (const Option<O>& opt : table) {
    const py::str key(opt.name);
    if (!kwargs.contains(key)) continue;
    try {
      opt.set(o, kwargs[key]);
    } catch (const py::cast_error&) {
      throw py::type_error(std::string(call) + "(): option '" + opt.name + "' got " +
                           std::string(py::str(py::type::of(kwargs[key]).attr("__name__"))) + " (" +
                           opt.doc + ")");
    }
    PyDict_DelItem(kwargs.ptr(), key.ptr());
  }
}
// Raises TypeError for the keywords left in `kwargs` (none of the call's tables knew them).
void reject_unknown(const py::dict& kwargs, const char* call);

// "name=default: doc" lines of a table, the defaults read from `defaults` (a docstring part).
template <class O>
std::string options_doc(const OptionTable<O>& table, O defaults) {
  std::string s;
  for (const Option<O>& opt : table)
    s += "    " + opt.name + "=" + std::string(py::repr(opt.get(defaults))) + ": " + opt.doc + "\n";
  return s;
}
// {name: default} of a table.
template <class O>
py::dict options_dict(const OptionTable<O>& table, O defaults) {
  py::dict d;
  for (const Option<O>& opt : table) d[py::str(opt.name)] = opt.get(defaults);
  return d;
}

// --- progress -----------------------------------------------------------------------------

// The `progress` keyword of a long call: None prints "stage done/total" on stderr when it is a
// terminal, False prints nothing, a callable is called as progress(stage, done, total). The
// returned function may be called without the GIL; it takes it, and raises KeyboardInterrupt
// (through py::error_already_set) when Ctrl-C was pressed, whatever `progress` is.
std::function<void(const std::string&, std::size_t, std::size_t)> progress_reporter(
    const py::object& progress);

// --- the stages ---------------------------------------------------------------------------

void bind_core(py::module_& m);      // core.cpp: camera geometry, images, camera estimate
void bind_features(py::module_& m);  // features.cpp: FeaturePipeline, extract, match
void bind_tracking(py::module_& m);  // tracking.cpp: Tracker, Dataset
void bind_calib(py::module_& m);     // calib.cpp: calibrate, CalibrationFilter, results
void bind_pipeline(py::module_& m);  // pipeline.cpp: calibrate_dataset, simulate

}  // namespace omnivert::python
