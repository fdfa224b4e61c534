// Bindings of the frame pipeline (Sec. 2-3: mirror circle, radial lines, descriptors) and of
// the descriptor matcher (Sec. 4).

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/match/matcher.hpp"
#include "options.hpp"

namespace omnivert::python {

namespace {

// A per-line field of a frame as a numpy array.
template <class T, class F>
py::array_t<T> per_line(const FrameFeatures& f, F get) {
  py::array_t<T> a(static_cast<py::ssize_t>(f.lines.size()));
  auto v = a.mutable_unchecked();
  for (std::size_t i = 0; i < f.lines.size(); ++i) v(static_cast<py::ssize_t>(i)) = get(f.lines[i]);
  return a;
}

// A camera geometry from a CameraGeometry, a sensor.yaml path, or None (every field estimated).
CameraGeometry geometry_of(const py::object& g) {
  if (g.is_none()) return CameraGeometry{};
  if (py::isinstance<py::str>(g)) return load_camera_geometry(g.cast<std::string>());
  return g.cast<CameraGeometry>();
}

FeaturePipelineOptions pipeline_options(py::dict& kwargs, const char* call) {
  FeaturePipelineOptions o;
  apply_options(extraction_table(), o, kwargs, call);
  reject_unknown(kwargs, call);
  check_valid(o);
  return o;
}

// One image through the pipeline; InputError with the pipeline's reason when the image does
// not fit the camera or its mirror is not found.
FrameFeatures process(FeaturePipeline& pipe, const py::handle& image) {
  py::object keep;
  const cv::Mat view = image_view(image, &keep);
  FrameFeatures f;
  std::string why;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = pipe.process(view, f, &why);
  }
  if (!ok) throw InputError("image: " + why);
  return f;
}

void bind_frame_features(py::module_& m) {
  py::class_<VerticalLine>(m, "VerticalLine", "One radial line of a frame (Sec. 2).")
      .def_readonly("image_angle", &VerticalLine::image_angle, "[rad], (-pi, pi]")
      .def_readonly("bearing", &VerticalLine::bearing, "camera bearing [rad], (-pi, pi]")
      .def_readonly("edge_pixels", &VerticalLine::edge_pixels)
      .def_readonly(
          "annulus_fraction", &VerticalLine::annulus_fraction, "edge_pixels / (R_max - R_min)")
      .def_readonly("r_inner", &VerticalLine::r_inner)
      .def_readonly("r_outer", &VerticalLine::r_outer)
      .def_readonly("fit_rms_px", &VerticalLine::fit_rms_px)
      .def_readonly("significance", &VerticalLine::significance)
      .def_readonly("polarity", &VerticalLine::polarity)
      .def_readonly("crowded", &VerticalLine::crowded);
  py::class_<FrameFeatures>(m,
                            "FrameFeatures",
                            "A frame's mirror circle, vertical lines and descriptors (row i of "
                            "descriptors describes line i).")
      .def_property_readonly(
          "center", [](const FrameFeatures& f) { return Eigen::Vector2d(f.circle.center); })
      .def_property_readonly("r_min", [](const FrameFeatures& f) { return f.circle.r_min; })
      .def_property_readonly("r_max", [](const FrameFeatures& f) { return f.circle.r_max; })
      .def_property_readonly("rim_radius",
                             [](const FrameFeatures& f) { return f.circle.rim_radius; })
      .def_readonly("lines", &FrameFeatures::lines)
      .def_property_readonly(
          "descriptors",
          [](const FrameFeatures& f) -> const DescriptorMatrix& { return f.descriptors; },
          py::return_value_policy::reference_internal,
          "(N, 192) float32, read-only view")
      .def_property_readonly("bearings",
                             [](const FrameFeatures& f) {
                               return per_line<double>(
                                   f, [](const VerticalLine& l) { return l.bearing; });
                             })
      .def_property_readonly("image_angles",
                             [](const FrameFeatures& f) {
                               return per_line<double>(
                                   f, [](const VerticalLine& l) { return l.image_angle; });
                             })
      .def_property_readonly("edge_pixels",
                             [](const FrameFeatures& f) {
                               return per_line<int>(
                                   f, [](const VerticalLine& l) { return l.edge_pixels; });
                             })
      .def_property_readonly("r_inner",
                             [](const FrameFeatures& f) {
                               return per_line<double>(
                                   f, [](const VerticalLine& l) { return l.r_inner; });
                             })
      .def_property_readonly("r_outer",
                             [](const FrameFeatures& f) {
                               return per_line<double>(
                                   f, [](const VerticalLine& l) { return l.r_outer; });
                             })
      .def_property_readonly("significance",
                             [](const FrameFeatures& f) {
                               return per_line<double>(
                                   f, [](const VerticalLine& l) { return l.significance; });
                             })
      .def_property_readonly("polarity",
                             [](const FrameFeatures& f) {
                               return per_line<int>(
                                   f, [](const VerticalLine& l) { return l.polarity; });
                             })
      .def_property_readonly("crowded",
                             [](const FrameFeatures& f) {
                               return per_line<bool>(
                                   f, [](const VerticalLine& l) { return l.crowded; });
                             })
      .def("__len__", [](const FrameFeatures& f) { return f.lines.size(); })
      .def("__repr__", [](const FrameFeatures& f) {
        return "FrameFeatures(" + std::to_string(f.lines.size()) + " lines, centre (" +
               std::to_string(f.circle.center.x()) + ", " + std::to_string(f.circle.center.y()) +
               "))";
      });
}

}  // namespace

void bind_features(py::module_& m) {
  bind_frame_features(m);
  const std::string doc = options_doc(extraction_table(), FeaturePipelineOptions{});
  py::class_<FeaturePipeline>(m, "FeaturePipeline")
      .def(py::init([](const py::object& geometry, py::kwargs kw) {
             py::dict kwargs = kw;
             return std::make_unique<FeaturePipeline>(geometry_of(geometry),
                                                      pipeline_options(kwargs, "FeaturePipeline"));
           }),
           py::arg("geometry") = py::none(),
           ("One frame from pixels to features, keeping what a video needs (the rim of the first "
            "frame, the previous centre). geometry: a CameraGeometry, a sensor.yaml path or None. "
            "Keyword options (the CLI's flags):\n" +
            doc)
               .c_str())
      .def("process",
           &process,
           py::arg("image"),
           "FrameFeatures of one image (numpy, uint8/uint16/float32, grey or BGR; not copied). "
           "InputError with the reason when the image does not fit the camera.")
      .def_property_readonly("geometry", &FeaturePipeline::geometry);
  m.def(
      "extract",
      [](const py::handle& image, const py::object& geometry, py::kwargs kw) {
        py::dict kwargs = kw;
        FeaturePipeline pipe(geometry_of(geometry), pipeline_options(kwargs, "extract"));
        return process(pipe, image);
      },
      py::arg("image"),
      py::arg("geometry") = py::none(),
      ("The vertical lines of one image, as `omnivert extract`: FrameFeatures. geometry: a "
       "CameraGeometry, a sensor.yaml path or None. Keyword options:\n" +
       doc)
          .c_str());
  m.def(
      "match",
      [](const py::array_t<float, py::array::c_style | py::array::forcecast>& query,
         const py::array_t<float, py::array::c_style | py::array::forcecast>& candidates,
         double f1,
         double f2,
         double f3,
         double partial_area_scale,
         double partial_side_scale) {
        if (query.ndim() != 2 || candidates.ndim() != 2 || query.shape(1) != candidates.shape(1))
          throw InputError("match: expected two (N, D) descriptor arrays of one width D");
        MatchOptions o;
        o.f1 = f1;
        o.f2 = f2;
        o.f3 = f3;
        o.partial_area_scale = partial_area_scale;
        o.partial_side_scale = partial_side_scale;
        check_valid(o);
        using Map = Eigen::Map<const DescriptorMatrix>;
        const Map q(query.data(), query.shape(0), query.shape(1));
        const Map c(candidates.data(), candidates.shape(0), candidates.shape(1));
        std::vector<MatchResult> r;
        Matcher(o).match(q, c, &r);
        const auto n = static_cast<py::ssize_t>(r.size());
        py::array_t<int> best(n);
        py::array_t<float> dist(n), second(n), mean(n);
        py::array_t<bool> accepted(n);
        py::list verdicts;
        for (py::ssize_t i = 0; i < n; ++i) {
          const MatchResult& x = r[static_cast<std::size_t>(i)];
          best.mutable_at(i) = x.best;
          dist.mutable_at(i) = x.min_distance;
          second.mutable_at(i) = x.second_distance;
          mean.mutable_at(i) = x.mean_distance;
          accepted.mutable_at(i) = x.accepted();
          verdicts.append(to_string(x.verdict));
        }
        py::dict d;
        d["best"] = best;
        d["distance"] = dist;
        d["second_distance"] = second;
        d["mean_distance"] = mean;
        d["accepted"] = accepted;
        d["verdict"] = verdicts;
        return d;
      },
      py::arg("query"),
      py::arg("candidates"),
      py::arg("f1") = MatchOptions{}.f1,
      py::arg("f2") = MatchOptions{}.f2,
      py::arg("f3") = MatchOptions{}.f3,
      py::arg("partial_area_scale") = MatchOptions{}.partial_area_scale,
      py::arg("partial_side_scale") = MatchOptions{}.partial_side_scale,
      "Each query descriptor's nearest candidate (eq. 6, or the occluder-tolerant distance with "
      "partial_area_scale) and the verdict of tests 1-3 (eq. 8-10; "
      "defaults: the paper's Table 2): a dict of arrays best, distance, second_distance, "
      "mean_distance, accepted and the list verdict.");
}

}  // namespace omnivert::python
