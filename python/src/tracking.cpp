// Bindings of the tracker fed frame by frame (Sec. 4, 9.1) and of the dataset reader
// (dataset/dataset.hpp: cam0/, wheel0/, ground_truth/).

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/match/tracker.hpp"
#include "options.hpp"
#include "results.hpp"

namespace omnivert::python {

namespace {

// The tracker and the descriptor width of the frames it was given (a frame passed as None
// has no lines and that width).
struct PyTracker {
  explicit PyTracker(TrackerOptions o) : tracker(std::move(o)) {}
  Tracker tracker;
  Eigen::Index width = kPaperDescriptorSize;
};

// The tracker's decisions for the lines of one frame, in line order.
struct Assignments {
  std::vector<TrackAssignment> rows;
};

template <class T, class F>
py::array_t<T> column(const Assignments& a, F get) {
  py::array_t<T> out(static_cast<py::ssize_t>(a.rows.size()));
  for (std::size_t i = 0; i < a.rows.size(); ++i)
    out.mutable_at(static_cast<py::ssize_t>(i)) = get(a.rows[i]);
  return out;
}

Assignments add_frame(PyTracker& t, const FrameFeatures* frame, double d_right, double d_left) {
  FrameFeatures empty;
  if (frame == nullptr) empty.descriptors.resize(0, t.width);
  const FrameFeatures& f = frame ? *frame : empty;
  Assignments a;
  {
    py::gil_scoped_release release;
    t.tracker.add_frame(f, WheelIncrement{d_right, d_left}, &a.rows);
  }
  if (f.descriptors.cols() > 0) t.width = f.descriptors.cols();
  return a;
}

}  // namespace

py::dict stats_dict(const TrackerStats& s) {
  py::dict d;
  d["frames"] = s.frames;
  d["lines"] = s.lines;
  d["matched_previous"] = s.matched_previous;
  d["matched_look_back"] = s.matched_look_back;
  d["new_tracks"] = s.new_tracks;
  d["rejected_test1"] = s.rejected_test1;
  d["rejected_test2"] = s.rejected_test2;
  d["rejected_test3"] = s.rejected_test3;
  d["rejected_mutual"] = s.rejected_mutual;
  d["rejected_claimed"] = s.rejected_claimed;
  d["rejected_gate"] = s.rejected_gate;
  d["rejected_continuity"] = s.rejected_continuity;
  d["rejected_fork"] = s.rejected_fork;
  return d;
}

namespace {

void bind_tracker(py::module_& m) {
  py::class_<Assignments>(
      m, "TrackAssignments", "The tracker's decision for each line of a frame, in line order.")
      .def_property_readonly("track_ids",
                             [](const Assignments& a) {
                               return column<std::int64_t>(
                                   a, [](const TrackAssignment& r) { return r.track_id; });
                             })
      .def_property_readonly("frames_back",
                             [](const Assignments& a) {
                               return column<int>(
                                   a, [](const TrackAssignment& r) { return r.frames_back; });
                             })
      .def_property_readonly("matched_line",
                             [](const Assignments& a) {
                               return column<int>(
                                   a, [](const TrackAssignment& r) { return r.matched_line; });
                             })
      .def_property_readonly("distance",
                             [](const Assignments& a) {
                               return column<float>(
                                   a, [](const TrackAssignment& r) { return r.distance; });
                             })
      .def_property_readonly("is_new",
                             [](const Assignments& a) {
                               return column<bool>(
                                   a, [](const TrackAssignment& r) { return r.is_new(); });
                             })
      .def("__len__", [](const Assignments& a) { return a.rows.size(); });

  const std::string doc = options_doc(tracker_table(), recommended_dataset_tracker_options());
  py::class_<PyTracker>(m, "Tracker")
      .def(py::init([](double wheel_base, py::kwargs kw) {
             py::dict kwargs = kw;
             TrackerOptions o = tracker_from_kwargs(kwargs, wheel_base, false, "Tracker");
             reject_unknown(kwargs, "Tracker");
             check_valid(o);
             return std::make_unique<PyTracker>(std::move(o));
           }),
           py::arg("wheel_base") = 0.0,
           ("Tracks lines frame by frame (Sec. 4, 9.1). wheel_base [m] > 0 turns on the odometry "
            "gate of the recommended rules. rules='recommended' (default) or 'paper', then the "
            "keyword options (defaults of the recommended rules):\n" +
            doc)
               .c_str())
      .def("add_frame",
           &add_frame,
           py::arg("features").none(true),
           py::arg("d_right") = 0.0,
           py::arg("d_left") = 0.0,
           "The next frame's FrameFeatures (None: a frame that could not be read) and the wheel "
           "travel [m] since the previous frame; returns TrackAssignments.")
      .def(
          "set_camera_yaw",
          [](PyTracker& t, double yaw) { t.tracker.set_camera_yaw(yaw); },
          py::arg("yaw"),
          "The camera's yaw on the robot (phi + psi) [rad] from the next frame on, e.g. a "
          "running calibration's; nan: estimated by the tracker again. Lines already located "
          "keep the yaw they were located with.")
      .def_property_readonly("stats",
                             [](const PyTracker& t) { return stats_dict(t.tracker.stats()); })
      .def_property_readonly("frames_seen",
                             [](const PyTracker& t) { return t.tracker.frames_seen(); })
      .def_property_readonly("tracks_created",
                             [](const PyTracker& t) { return t.tracker.tracks_created(); });
}

py::object ground_truth(const dataset::Dataset& d) {
  if (!d.ground_truth()) return py::none();
  const dataset::GroundTruth& g = *d.ground_truth();
  py::dict out;
  if (g.extrinsics) {
    py::dict e;
    e["phi"] = g.extrinsics->phi;
    e["rho"] = g.extrinsics->rho;
    e["psi"] = g.extrinsics->psi;
    out["extrinsics"] = e;
  } else {
    out["extrinsics"] = py::none();
  }
  const auto n = static_cast<py::ssize_t>(g.poses.size());
  py::array_t<std::int64_t> t(n);
  py::array_t<double> pose({n, py::ssize_t{3}});
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& p = g.poses[static_cast<std::size_t>(i)];
    t.mutable_at(i) = p.timestamp_ns;
    pose.mutable_at(i, 0) = p.x;
    pose.mutable_at(i, 1) = p.y;
    pose.mutable_at(i, 2) = p.theta;
  }
  out["pose_timestamps"] = t;
  out["poses"] = pose;
  return out;
}

void bind_dataset(py::module_& m) {
  using dataset::Dataset;
  py::class_<Dataset>(m,
                      "Dataset",
                      "A dataset folder (cam0/, wheel0/, optional ground_truth/; "
                      "docs/dataset-format.md), checked on load.")
      .def(py::init([](const std::string& path,
                       bool require_wheel,
                       bool allow_missing_images,
                       bool check_all_images) {
             dataset::LoadOptions o;
             o.require_wheel = require_wheel;
             o.allow_missing_images = allow_missing_images;
             o.check_all_images = check_all_images;
             py::gil_scoped_release release;
             return Dataset::load(path, o);
           }),
           py::arg("path"),
           py::arg("require_wheel") = true,
           py::arg("allow_missing_images") = false,
           py::arg("check_all_images") = false)
      .def_property_readonly("root", &Dataset::root)
      .def_property_readonly("camera", &Dataset::camera)
      .def("__len__", &Dataset::size)
      .def_property_readonly("timestamps",
                             [](const Dataset& d) {
                               py::array_t<std::int64_t> t(static_cast<py::ssize_t>(d.size()));
                               for (std::size_t i = 0; i < d.size(); ++i)
                                 t.mutable_at(static_cast<py::ssize_t>(i)) =
                                     d.images()[i].timestamp_ns;
                               return t;
                             })
      .def_property_readonly("image_paths",
                             [](const Dataset& d) {
                               std::vector<std::string> p;
                               for (const auto& r : d.images()) p.push_back(r.path);
                               return p;
                             })
      .def(
          "image",
          [](const Dataset& d, std::size_t i) {
            if (i >= d.size())
              throw py::index_error("image " + std::to_string(i) + " of " +
                                    std::to_string(d.size()));
            cv::Mat1b img;
            {
              py::gil_scoped_release release;
              img = d.image(i);
            }
            return to_numpy(img);
          },
          py::arg("i"),
          "Image i as 8-bit grey (height, width) uint8.")
      .def_property_readonly("has_wheel", &Dataset::has_wheel)
      .def_property_readonly("wheel_base",
                             [](const Dataset& d) { return d.wheel_sensor().wheel_base; })
      .def_property_readonly("odometry_k",
                             [](const Dataset& d) { return d.wheel_sensor().odometry_k; })
      .def_property_readonly(
          "wheel_timestamps",
          [](const Dataset& d) {
            py::array_t<std::int64_t> t(static_cast<py::ssize_t>(d.wheel().size()));
            for (std::size_t i = 0; i < d.wheel().size(); ++i)
              t.mutable_at(static_cast<py::ssize_t>(i)) = d.wheel()[i].timestamp_ns;
            return t;
          })
      .def_property_readonly(
          "wheel_travel",
          [](const Dataset& d) {
            Eigen::MatrixX2d w(d.wheel().size(), 2);
            for (std::size_t i = 0; i < d.wheel().size(); ++i)
              w.row(static_cast<Eigen::Index>(i)) << d.wheel()[i].travel.left,
                  d.wheel()[i].travel.right;
            return w;
          },
          "(M, 2): cumulative travel (left, right) [m] of each wheel sample")
      .def_property_readonly(
          "travel_at_images",
          [](const Dataset& d) {
            Eigen::MatrixX2d w(d.size(), 2);
            const auto& t = d.travel_at_images();
            for (std::size_t i = 0; i < t.size(); ++i)
              w.row(static_cast<Eigen::Index>(i)) << t[i].left, t[i].right;
            return w;
          },
          "(N, 2): cumulative travel (left, right) [m] at each image")
      .def_property_readonly(
          "increments",
          [](const Dataset& d) {
            Eigen::MatrixX2d w = Eigen::MatrixX2d::Zero(static_cast<Eigen::Index>(d.size()), 2);
            const auto& t = d.travel_at_images();
            for (std::size_t i = 1; i < t.size(); ++i) {
              const WheelIncrement inc =
                  increment_between(t[i - 1].left, t[i - 1].right, t[i].left, t[i].right);
              w.row(static_cast<Eigen::Index>(i)) << inc.d_right, inc.d_left;
            }
            return w;
          },
          "(N, 2): wheel travel (d_right, d_left) [m] since the previous image (0 for the first)")
      .def_property_readonly("ground_truth", &ground_truth)
      .def_property_readonly("notes", &Dataset::notes);
}

}  // namespace

void bind_tracking(py::module_& m) {
  bind_tracker(m);
  bind_dataset(m);
}

}  // namespace omnivert::python
