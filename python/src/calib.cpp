// Bindings of the estimator (Sec. 7-8): calibrate() from bearings and wheel increments, the
// frame-by-frame CalibrationFilter (the EKF of Sec. 8.2), and their results with the verdicts
// of Sec. 8.1.

#include <cmath>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/pipeline/calibration_report.hpp"
#include "options.hpp"
#include "results.hpp"

namespace omnivert::python {

py::dict history_dict(const std::vector<calib::FrameEstimate>& history) {
  const auto n = static_cast<py::ssize_t>(history.size());
  py::array_t<int> frame(n), features(n), updates(n), rejected(n), fresh(n), guarded(n);
  py::array_t<double> phi(n), rho(n), psi(n), s_phi(n), s_rho(n), s_psi(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const calib::FrameEstimate& h = history[static_cast<std::size_t>(i)];
    frame.mutable_at(i) = h.frame;
    phi.mutable_at(i) = h.extrinsics.phi;
    rho.mutable_at(i) = h.extrinsics.rho;
    psi.mutable_at(i) = h.extrinsics.psi;
    s_phi.mutable_at(i) = std::sqrt(std::max(h.covariance(0, 0), 0.0));
    s_rho.mutable_at(i) = std::sqrt(std::max(h.covariance(1, 1), 0.0));
    s_psi.mutable_at(i) = std::sqrt(std::max(h.covariance(2, 2), 0.0));
    features.mutable_at(i) = h.num_features;
    updates.mutable_at(i) = h.num_updates;
    rejected.mutable_at(i) = h.num_rejected;
    fresh.mutable_at(i) = h.num_new;
    guarded.mutable_at(i) = h.num_guarded;
  }
  py::dict d;
  d["frame"] = frame;
  d["phi"] = phi;
  d["rho"] = rho;
  d["psi"] = psi;
  d["sigma_phi"] = s_phi;
  d["sigma_rho"] = s_rho;
  d["sigma_psi"] = s_psi;
  d["features"] = features;
  d["updates"] = updates;
  d["rejected"] = rejected;
  d["new"] = fresh;
  d["guarded"] = guarded;
  return d;
}

namespace {

using calib::CalibrationOptions;

const char* verdict_name(calib::NoiseVerdict v) {
  switch (v) {
    case calib::NoiseVerdict::kMoreNoise:
      return "more noise";
    case calib::NoiseVerdict::kLessNoise:
      return "less noise";
    default:
      return "agrees";
  }
}

CalibrationOptions calibration_options(py::dict& kwargs, const char* call) {
  CalibrationOptions o = calib::recommended_options();
  apply_options(robot_table(), o, kwargs, call);
  apply_options(calibration_table(), o, kwargs, call);
  reject_unknown(kwargs, call);
  check_valid(o);
  return o;
}

// FrameInputs from (F, 2) increments (d_right, d_left) and (K, 3|4) observations (frame,
// track id, bearing[, sigma scale]).
calib::CalibrationRun run_of(const py::array_t<double, py::array::forcecast>& increments,
                             const py::array_t<double, py::array::forcecast>& observations) {
  if (increments.ndim() != 2 || increments.shape(1) != 2)
    throw InputError("increments: expected an (F, 2) array of (d_right, d_left) [m]");
  if (observations.ndim() != 2 || (observations.shape(1) != 3 && observations.shape(1) != 4))
    throw InputError("observations: expected a (K, 3) array of (frame, track id, bearing [rad])");
  calib::CalibrationRun run;
  run.frames.resize(static_cast<std::size_t>(increments.shape(0)));
  for (py::ssize_t f = 0; f < increments.shape(0); ++f) {
    run.frames[static_cast<std::size_t>(f)].d_right = increments.at(f, 0);
    run.frames[static_cast<std::size_t>(f)].d_left = increments.at(f, 1);
  }
  for (py::ssize_t k = 0; k < observations.shape(0); ++k) {
    const double frame = observations.at(k, 0), id = observations.at(k, 1);
    const std::string row = "observations row " + std::to_string(k) + ": ";
    if (!(frame >= 0 && frame < static_cast<double>(run.frames.size())) ||
        frame != std::floor(frame))
      throw InputError(row + "frame " + std::to_string(frame) + " is not one of the " +
                       std::to_string(run.frames.size()) + " frames of increments");
    if (!(id >= 0 && id < 2147483647.0) || id != std::floor(id))
      throw InputError(row + "track id " + std::to_string(id) + " is not an integer >= 0");
    calib::BearingObservation o{static_cast<int>(id), observations.at(k, 2)};
    if (observations.shape(1) == 4) o.sigma_scale = observations.at(k, 3);
    run.frames[static_cast<std::size_t>(frame)].observations.push_back(o);
  }
  return run;
}

py::object summary_of(const Calibration& c) {
  pipeline::ReportInputs in;
  in.options = c.options;
  in.truth = c.truth;
  in.exit_code = c.result.observable() ? 0 : 3;
  return py::module_::import("json").attr("loads")(pipeline::summary_json(c.result, in));
}

void bind_results(py::module_& m) {
  py::class_<calib::Extrinsics>(m,
                                "Extrinsics",
                                "The camera-to-odometry extrinsics of Fig. 19 (docs/theory/"
                                "conventions.md): camera centre at rho (cos phi, sin phi), camera "
                                "yaw phi + psi.")
      .def(py::init([](double phi, double rho, double psi) {
             return calib::Extrinsics{phi, rho, psi};
           }),
           py::arg("phi") = 0.0,
           py::arg("rho") = 0.2,
           py::arg("psi") = 0.0)
      .def_readwrite("phi", &calib::Extrinsics::phi)
      .def_readwrite("rho", &calib::Extrinsics::rho)
      .def_readwrite("psi", &calib::Extrinsics::psi)
      .def_property_readonly("position", &calib::Extrinsics::position)
      .def_property_readonly("yaw", &calib::Extrinsics::yaw)
      .def_property_readonly("T_base_cam", &calib::Extrinsics::T_base_cam)
      .def("__repr__", [](const calib::Extrinsics& e) {
        return "Extrinsics(phi=" + std::to_string(e.phi) + ", rho=" + std::to_string(e.rho) +
               ", psi=" + std::to_string(e.psi) + ")";
      });
  py::class_<calib::ParameterVerdict>(m, "ParameterVerdict")
      .def_readonly("determined", &calib::ParameterVerdict::determined)
      .def_readonly(
          "crlb", &calib::ParameterVerdict::crlb, "Cramer-Rao sigma (inf: not determined)");
  py::class_<calib::ObservabilityReport>(
      m, "ObservabilityReport", "The verdict of Sec. 8.1 and the Cramer-Rao bounds.")
      .def_readonly("phi", &calib::ObservabilityReport::phi)
      .def_readonly("rho", &calib::ObservabilityReport::rho)
      .def_readonly("psi", &calib::ObservabilityReport::psi)
      .def_readonly("yaw", &calib::ObservabilityReport::yaw)
      .def_readonly("x", &calib::ObservabilityReport::x)
      .def_readonly("y", &calib::ObservabilityReport::y)
      .def_readonly("information", &calib::ObservabilityReport::information)
      .def_readonly("crlb_covariance", &calib::ObservabilityReport::crlb_covariance)
      .def_readonly("heading_range", &calib::ObservabilityReport::heading_range)
      .def_readonly("rank", &calib::ObservabilityReport::rank)
      .def_readonly("condition", &calib::ObservabilityReport::condition)
      .def_readonly("message", &calib::ObservabilityReport::message)
      .def_property_readonly("all_determined", &calib::ObservabilityReport::all_determined);

  py::class_<Calibration>(m,
                          "CalibrationResult",
                          "The extrinsics with their covariance, the verdicts and the filter's "
                          "history (calib::CalibrationResult).")
      .def_property_readonly("extrinsics", [](const Calibration& c) { return c.result.extrinsics; })
      .def_property_readonly(
          "covariance",
          [](const Calibration& c) { return c.result.covariance; },
          "3x3 covariance of (phi, rho, psi)")
      .def_property_readonly(
          "sigmas",
          [](const Calibration& c) {
            return Eigen::Vector3d(c.result.covariance.diagonal().cwiseMax(0.0).cwiseSqrt());
          })
      .def_property_readonly("observable",
                             [](const Calibration& c) { return c.result.observable(); })
      .def_property_readonly("observability",
                             [](const Calibration& c) { return c.result.observability; })
      .def_property_readonly("refined", [](const Calibration& c) { return c.result.refined; })
      .def_property_readonly(
          "source",
          [](const Calibration& c) {
            return c.result.refined && c.result.refinement.covariance_ok ? "refinement" : "filter";
          })
      .def_property_readonly("filter_extrinsics",
                             [](const Calibration& c) { return c.result.filter.extrinsics; })
      .def_property_readonly("filter_covariance",
                             [](const Calibration& c) { return c.result.filter.covariance; })
      .def_property_readonly("noise_check",
                             [](const Calibration& c) {
                               const calib::NoiseCheckReport& n = c.result.noise_check;
                               py::dict d;
                               d["checked"] = n.checked;
                               d["applied"] = n.applied;
                               d["verdict"] = verdict_name(n.verdict);
                               // None, not NaN, when the check was not made.
                               d["scale"] = std::isfinite(n.check.scale)
                                                ? py::object(py::float_(n.check.scale))
                                                : py::object(py::none());
                               d["ratio"] = n.ratio;
                               d["line"] = pipeline::noise_check_line(c.result);
                               return d;
                             })
      .def_property_readonly("warnings",
                             [](const Calibration& c) { return calib::result_warnings(c.result); })
      .def_property_readonly(
          "history",
          [](const Calibration& c) { return history_dict(c.result.filter.history); },
          "the filter's estimate frame by frame: states.csv's columns (Fig. 25)")
      .def_property_readonly("summary", &summary_of, "summary.json's content as a dict")
      .def("brief_report", [](const Calibration& c) { return c.result.BriefReport(); })
      .def("full_report", [](const Calibration& c) { return c.result.FullReport(); })
      .def(
          "write_extrinsics_yaml",
          [](const Calibration& c, const std::string& path) {
            calib::write_extrinsics_yaml(path, c.result);
          },
          py::arg("path"),
          "extrinsics.yaml (docs/outputs.md), written atomically")
      .def("__repr__",
           [](const Calibration& c) { return "CalibrationResult:\n" + c.result.BriefReport(); });
}

void bind_filter(py::module_& m, const std::string& doc) {
  py::class_<calib::CalibrationFilter>(m, "CalibrationFilter")
      .def(py::init([](py::kwargs kw) {
             py::dict kwargs = kw;
             return std::make_unique<calib::CalibrationFilter>(
                 calibration_options(kwargs, "CalibrationFilter"));
           }),
           ("The self-calibration EKF of Sec. 8.2, fed frame by frame as a robot drives. Keyword "
            "options:\n" +
            doc)
               .c_str())
      .def(
          "process",
          [](calib::CalibrationFilter& f,
             double d_right,
             double d_left,
             const std::vector<int>& track_ids,
             const std::vector<double>& bearings) {
            if (track_ids.size() != bearings.size())
              throw InputError("process: " + std::to_string(track_ids.size()) + " track ids but " +
                               std::to_string(bearings.size()) + " bearings");
            calib::FrameInput in{.d_right = d_right, .d_left = d_left};
            for (std::size_t i = 0; i < bearings.size(); ++i)
              in.observations.push_back({track_ids[i], bearings[i]});
            py::gil_scoped_release release;
            f.process(in);
          },
          py::arg("d_right"),
          py::arg("d_left"),
          py::arg("track_ids") = std::vector<int>{},
          py::arg("bearings") = std::vector<double>{},
          "One image: wheel travel [m] since the previous image, the track ids of its lines and "
          "their bearings [rad].")
      .def(
          "finish",
          [](calib::CalibrationFilter& f) {
            py::gil_scoped_release release;
            f.finish();
          },
          "End of the run: solves a pending start-up window. Call once after the last frame.")
      .def_property_readonly("extrinsics", &calib::CalibrationFilter::extrinsics)
      .def_property_readonly("covariance", &calib::CalibrationFilter::covariance)
      .def_property_readonly(
          "history", [](const calib::CalibrationFilter& f) { return history_dict(f.history()); })
      .def_property_readonly("frames_processed", &calib::CalibrationFilter::frames_processed)
      .def_property_readonly("window_frames", &calib::CalibrationFilter::window_frames)
      .def_property_readonly("window_failure", &calib::CalibrationFilter::window_failure);
}

}  // namespace

void bind_calib(py::module_& m) {
  bind_results(m);
  const std::string doc = options_doc(robot_table(), calib::recommended_options()) +
                          options_doc(calibration_table(), calib::recommended_options());
  m.def(
      "calibrate",
      [](const py::array_t<double, py::array::forcecast>& increments,
         const py::array_t<double, py::array::forcecast>& observations,
         py::kwargs kw) {
        py::dict kwargs = kw;
        Calibration c;
        c.options = calibration_options(kwargs, "calibrate");
        const calib::CalibrationRun run = run_of(increments, observations);
        py::gil_scoped_release release;
        c.result = calib::calibrate(run, c.options);
        return c;
      },
      py::arg("increments"),
      py::arg("observations"),
      ("The extrinsics from a run (Sec. 7-8): increments (F, 2) wheel travel (d_right, d_left) "
       "[m] since the previous image, observations (K, 3) rows (frame, track id, bearing [rad]) "
       "(a 4th column: the bearing's sigma scale). Returns a CalibrationResult. Keyword options "
       "(the defaults of `omnivert calibrate`):\n" +
       doc)
          .c_str());
  bind_filter(m, doc);
}

}  // namespace omnivert::python
