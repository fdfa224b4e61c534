// Bindings of the main jobs: calibrate_dataset (pipeline/calibrate_dataset.hpp, what `omnivert
// calibrate` runs) and simulate (sim/simulator.hpp, what `omnivert simulate` runs).

#include <filesystem>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "omnivert/sim/simulator.hpp"
#include "omnivert/viz/tracks_plot.hpp"
#include "options.hpp"
#include "results.hpp"

namespace omnivert::python {

namespace {

struct DatasetCalibration {
  pipeline::CalibrateDatasetResult job;
  Calibration calibration;
  py::object summary;
};

// The call as Python code, recorded in summary.json and report.html as the command.
std::string call_text(const std::string& dataset, const std::string& out, const py::dict& kwargs) {
  std::string s = "omnivert.calibrate_dataset(" + std::string(py::repr(py::str(dataset))) + ", " +
                  std::string(py::repr(py::str(out)));
  for (const auto& kv : kwargs)
    s += ", " + py::str(kv.first).cast<std::string>() + "=" + std::string(py::repr(kv.second));
  return s + ")";
}

DatasetCalibration calibrate_dataset(const std::string& dataset,
                                     const std::string& out,
                                     const py::object& progress,
                                     py::kwargs kw) {
  const char* call = "calibrate_dataset";
  py::dict kwargs = kw;
  pipeline::CalibrateDatasetOptions o;
  o.command = call_text(dataset, out, kwargs);
  apply_options(extraction_table(), o.features, kwargs, call);
  o.tracker = tracker_from_kwargs(kwargs, 0.0, true, call);
  apply_options(calibration_table(), o.calibration, kwargs, call);
  apply_options(dataset_job_table(), o, kwargs, call);
  reject_unknown(kwargs, call);
  check_valid(o.features);
  check_valid(o.calibration);
  const auto report = progress_reporter(progress);
  if (report) o.progress = report;
  DatasetCalibration r;
  {
    py::gil_scoped_release release;
    r.job = pipeline::calibrate_dataset(dataset, out, o);
  }
  r.calibration.result = r.job.calibration;
  r.calibration.options = o.calibration;
  r.calibration.truth = r.job.truth;
  const py::object path =
      py::module_::import("os").attr("path").attr("join")(r.job.out_dir, "summary.json");
  r.summary = py::module_::import("json").attr("loads")(
      py::module_::import("pathlib").attr("Path")(path).attr("read_text")("utf-8"));
  return r;
}

// tracks.csv's columns as numpy arrays.
py::dict track_columns(const std::vector<TrackRow>& rows) {
  const auto n = static_cast<py::ssize_t>(rows.size());
  py::array_t<std::int64_t> frame(n), stamp(n), id(n), matched_frame(n);
  py::array_t<double> bearing(n), angle(n), r_inner(n), r_outer(n), distance(n);
  py::array_t<int> edge_pixels(n), line(n), matched_line(n);
  py::array_t<bool> crowded(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const TrackRow& r = rows[static_cast<std::size_t>(i)];
    frame.mutable_at(i) = r.frame;
    stamp.mutable_at(i) = r.timestamp_ns;
    id.mutable_at(i) = r.track_id;
    bearing.mutable_at(i) = r.bearing;
    angle.mutable_at(i) = r.image_angle;
    edge_pixels.mutable_at(i) = r.edge_pixels;
    r_inner.mutable_at(i) = r.r_inner;
    r_outer.mutable_at(i) = r.r_outer;
    matched_frame.mutable_at(i) = r.matched_frame;
    distance.mutable_at(i) = r.distance;
    line.mutable_at(i) = r.line;
    matched_line.mutable_at(i) = r.matched_line;
    crowded.mutable_at(i) = r.crowded;
  }
  py::dict d;
  d["frame"] = frame;
  d["timestamp_ns"] = stamp;
  d["track_id"] = id;
  d["bearing"] = bearing;
  d["image_angle"] = angle;
  d["edge_pixels"] = edge_pixels;
  d["r_inner"] = r_inner;
  d["r_outer"] = r_outer;
  d["matched_frame"] = matched_frame;
  d["distance"] = distance;
  d["line"] = line;
  d["matched_line"] = matched_line;
  d["crowded"] = crowded;
  return d;
}

// `omnivert track DATASET [--out OUT]`: tracks.csv's rows as arrays, the counters, the warnings.
py::dict track_dataset(const std::string& dataset,
                       const py::object& out,
                       const py::object& progress,
                       py::kwargs kw) {
  const char* call = "track_dataset";
  py::dict kwargs = kw;
  pipeline::TrackDatasetOptions o;
  apply_options(extraction_table(), o.pipeline, kwargs, call);
  o.tracker = tracker_from_kwargs(kwargs, 0.0, true, call);
  apply_options(track_job_table(), o, kwargs, call);
  reject_unknown(kwargs, call);
  check_valid(o.pipeline);
  const auto report = progress_reporter(progress);
  std::function<void(std::size_t, std::size_t)> each;
  if (report)
    each = [&report](std::size_t done, std::size_t total) { report("track", done, total); };
  const std::string dir = out.is_none() ? std::string() : out.cast<std::string>();
  pipeline::TrackDatasetResult r;
  {
    py::gil_scoped_release release;
    dataset::LoadOptions lo;
    lo.require_wheel = false;
    lo.allow_missing_images = true;  // a missing frame is warned about and tracked with no lines
    r = pipeline::track_dataset(dataset::Dataset::load(dataset, lo), o, each);
    if (!dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(dir, ec);
      if (ec) throw InputError(dir, 0, "cannot create the output folder: " + ec.message());
      write_tracks_csv(std::filesystem::path(dir) / "tracks.csv", r.rows);
      viz::write_tracks_png(std::filesystem::path(dir) / "tracks.png", r.rows);
    }
  }
  py::dict d;
  d["tracks"] = track_columns(r.rows);
  d["stats"] = stats_dict(r.stats);
  d["frames"] = r.frames;
  d["frames_skipped"] = r.frames_skipped;
  d["warnings"] = r.warnings;
  return d;
}

py::dict simulate(const std::string& out,
                  const std::string& world,
                  const std::string& trajectory,
                  bool force,
                  const py::object& progress,
                  py::kwargs kw) {
  py::dict kwargs = kw;
  sim::SimConfig config;
  apply_options(simulation_table(), config, kwargs, "simulate");
  reject_unknown(kwargs, "simulate");
  const auto report = progress_reporter(progress);
  sim::SimSummary s;
  {
    py::gil_scoped_release release;
    const sim::World w = sim::load_world(world);
    const sim::Trajectory t = sim::load_trajectory(trajectory);
    std::function<void(int, int)> each;
    if (report)
      each = [&report](int done, int total) {
        report("simulate", static_cast<std::size_t>(done), static_cast<std::size_t>(total));
      };
    s = sim::simulate(w, t, config, out, force, each);
  }
  py::dict d;
  d["frames"] = s.frames;
  d["wheel_samples"] = s.wheel_samples;
  d["distance"] = s.distance;
  d["mean_lines"] = s.mean_lines;
  d["seconds"] = s.seconds;
  return d;
}

}  // namespace

void bind_pipeline(py::module_& m) {
  py::class_<DatasetCalibration>(m,
                                 "DatasetCalibration",
                                 "calibrate_dataset's result: the calibration, the counts, the "
                                 "warnings and summary.json as a dict.")
      .def_readonly("calibration", &DatasetCalibration::calibration)
      .def_property_readonly("extrinsics",
                             [](const DatasetCalibration& r) { return r.job.extrinsics(); })
      .def_property_readonly(
          "covariance", [](const DatasetCalibration& r) { return r.job.calibration.covariance; })
      .def_property_readonly(
          "observable", [](const DatasetCalibration& r) { return r.job.calibration.observable(); })
      .def_property_readonly("frames", [](const DatasetCalibration& r) { return r.job.frames; })
      .def_property_readonly("frames_skipped",
                             [](const DatasetCalibration& r) { return r.job.frames_skipped; })
      .def_property_readonly("detections",
                             [](const DatasetCalibration& r) { return r.job.detections; })
      .def_property_readonly("truth", [](const DatasetCalibration& r) { return r.job.truth; })
      .def_property_readonly("warnings", [](const DatasetCalibration& r) { return r.job.warnings; })
      .def_property_readonly("wrote_extrinsics",
                             [](const DatasetCalibration& r) { return r.job.wrote_extrinsics; })
      .def_property_readonly("out_dir", [](const DatasetCalibration& r) { return r.job.out_dir; })
      .def_property_readonly("time_offset",
                             [](const DatasetCalibration& r) {
                               py::dict d;
                               const auto& t = r.job.time_offset;
                               d["given"] = r.job.time_offset_given;
                               d["applied"] = r.job.time_offset_applied;
                               d["determined"] = t.determined;
                               d["refined"] = t.refined;
                               d["offset_s"] = t.determined ? py::cast(t.offset_s) : py::none();
                               d["sigma_s"] = t.determined && !r.job.time_offset_given
                                                  ? py::cast(t.sigma_s)
                                                  : py::none();
                               d["message"] = r.job.time_offset_message;
                               return d;
                             })
      .def_readonly("summary", &DatasetCalibration::summary, "summary.json as a dict")
      .def("brief_report", [](const DatasetCalibration& r) { return r.job.BriefReport(); })
      .def("__repr__", [](const DatasetCalibration& r) {
        return "DatasetCalibration:\n" + r.job.BriefReport();
      });

  const std::string doc =
      options_doc(extraction_table(), FeaturePipelineOptions{}) +
      "    rules='recommended': the tracker's rule set, 'recommended' or 'paper'\n" +
      options_doc(tracker_table(), recommended_dataset_tracker_options()) +
      options_doc(calibration_table(), calib::recommended_options()) +
      options_doc(dataset_job_table(), pipeline::CalibrateDatasetOptions{});
  m.def("calibrate_dataset",
        &calibrate_dataset,
        py::arg("dataset"),
        py::arg("out"),
        py::arg("progress") = py::none(),
        ("The main job, as `omnivert calibrate DATASET --out OUT`: tracks the dataset's lines, "
         "calibrates, writes every output file into out and returns a DatasetCalibration. "
         "InputError for bad input. progress: None (a line on a terminal), False, or "
         "progress(stage, done, total). Keyword options (the CLI's flags and defaults):\n" +
         doc)
            .c_str());
  m.def("track_dataset",
        &track_dataset,
        py::arg("dataset"),
        py::arg("out") = py::none(),
        py::arg("progress") = py::none(),
        "The lines of a dataset tracked, as `omnivert track DATASET --out OUT` (tracks.csv and "
        "tracks.png written into out when given): a dict with tracks (tracks.csv's columns as "
        "arrays), stats, frames, frames_skipped, warnings. Keyword options: the extraction's, "
        "rules and the tracker's, mask, tilt_check, tilt_correct_above, tilt_deg, "
        "tilt_direction_deg (as calibrate_dataset).");
  m.def("simulate",
        &simulate,
        py::arg("out"),
        py::arg("world") = "corridor",
        py::arg("trajectory") = "paper",
        py::arg("force") = false,
        py::arg("progress") = py::none(),
        ("Renders a dataset with ground truth into out, as `omnivert simulate` (world: corridor, "
         "office, hall or a YAML file; trajectory: paper, zigzag, straight, tour or a YAML file); "
         "returns {frames, wheel_samples, distance, mean_lines, seconds}. Keyword options:\n" +
         options_doc(simulation_table(), sim::SimConfig{}))
            .c_str());
}

}  // namespace omnivert::python
