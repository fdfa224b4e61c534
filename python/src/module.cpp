// The Python module `omnivert` (docs/python.md): the library's entry points with numpy arrays
// in and out. Each stage's bindings are in their own file (bind.hpp lists them).

#include <unistd.h>
#include <cstdio>

#include "bind.hpp"
#include "omnivert/core/error.hpp"
#include "options.hpp"

namespace omnivert::python {

void reject_unknown(const py::dict& kwargs, const char* call) {
  if (kwargs.empty()) return;
  std::string names;
  for (const auto& kv : kwargs)
    names += (names.empty() ? "'" : ", '") + py::str(kv.first).cast<std::string>() + "'";
  throw py::type_error(std::string(call) + "() got unexpected keyword argument(s) " + names +
                       " (omnivert.defaults('" + call + "') lists the options)");
}

std::function<void(const std::string&, std::size_t, std::size_t)> progress_reporter(
    const py::object& progress) {
  const bool callable = PyCallable_Check(progress.ptr()) != 0;
  if (!progress.is_none() && !callable && progress.cast<bool>())
    throw py::type_error("progress: expected None, False or a callable");
  const bool print = progress.is_none() && isatty(STDERR_FILENO) != 0;
  // Released with the GIL held: the last reference is the caller's copy of this function.
  auto callback = callable ? std::make_shared<py::object>(progress) : nullptr;
  return [callback, print](const std::string& stage, std::size_t done, std::size_t total) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
    if (callback) {
      (*callback)(stage, done, total);
    } else if (print && total > 0) {
      std::fprintf(stderr, "\r%s %zu/%zu%s", stage.c_str(), done, total, done == total ? "\n" : "");
      std::fflush(stderr);
    }
  };
}

namespace {

// omnivert.defaults(call): the keyword options of a call with their defaults.
py::dict defaults(const std::string& call) {
  py::dict d;
  auto add = [&d](const py::dict& part) {
    for (const auto& kv : part) d[kv.first] = kv.second;
  };
  const bool job = call == "calibrate_dataset" || call == "track_dataset";
  if (call == "extract" || call == "FeaturePipeline" || job)
    add(options_dict(extraction_table(), FeaturePipelineOptions{}));
  if (call == "Tracker" || job) {
    d["rules"] = "recommended";
    add(options_dict(tracker_table(), recommended_dataset_tracker_options()));
  }
  if (call == "calibrate" || call == "CalibrationFilter")
    add(options_dict(robot_table(), calib::recommended_options()));
  if (call == "calibrate" || call == "CalibrationFilter" || call == "calibrate_dataset")
    add(options_dict(calibration_table(), calib::recommended_options()));
  if (call == "calibrate_dataset")
    add(options_dict(dataset_job_table(), pipeline::CalibrateDatasetOptions{}));
  if (call == "track_dataset")
    add(options_dict(track_job_table(), pipeline::TrackDatasetOptions{}));
  if (call == "simulate") add(options_dict(simulation_table(), sim::SimConfig{}));
  if (d.empty()) throw py::value_error("defaults(): no call named '" + call + "'");
  return d;
}

}  // namespace

}  // namespace omnivert::python

PYBIND11_MODULE(omnivert, m) {
  namespace py = pybind11;
  using namespace omnivert::python;
  m.doc() =
      "omnivert: vertical lines in omnidirectional images, from pixels to the camera's pose on "
      "the robot (Scaramuzza, Siegwart, Martinelli, IJRR 2009). numpy arrays in and out; "
      "docs/python.md is the manual.";
  m.attr("__version__") = OMNIVERT_VERSION;

  // omnivert.InputError(ValueError): bad input (files, values), with the library's message
  // naming the file, the line and the problem; .file and .line as the library gives them.
  static py::exception<omnivert::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const omnivert::InputError& e) {
      py::object err = py::reinterpret_borrow<py::object>(input_error)(e.what());
      err.attr("file") = e.file();
      err.attr("line") = e.line();
      PyErr_SetObject(input_error.ptr(), err.ptr());
    }
  });
  m.def(
      "defaults",
      &defaults,
      py::arg("call"),
      "The keyword options of a call ('extract', 'FeaturePipeline', 'Tracker', 'track_dataset', "
      "'calibrate', 'CalibrationFilter', 'calibrate_dataset', 'simulate') with their defaults: the "
      "command-line tool's.");

  bind_core(m);
  bind_features(m);
  bind_tracking(m);
  bind_calib(m);
  bind_pipeline(m);
}
