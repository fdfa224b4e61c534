// The keyword option tables (options.hpp): each entry names a command-line flag's keyword,
// says what it sets and binds it to the library's field.

#include "options.hpp"

#include <map>
#include <optional>

namespace omnivert::python {

namespace {

// An option that takes one of the names of `choices`.
template <class O, class E, class Access>
Option<O> choice(std::string name,
                 std::string doc,
                 Access access,
                 std::map<std::string, E> choices) {
  const std::string key = name;
  return {std::move(name),
          std::move(doc),
          [access, choices](O& o) {
            for (const auto& [k, v] : choices)
              if (v == access(o)) return py::cast(k);
            return py::object(py::none());
          },
          [access, choices, key](O& o, const py::handle& v) {
            const auto it = choices.find(v.cast<std::string>());
            if (it == choices.end()) {
              std::string names;
              for (const auto& c : choices) names += (names.empty() ? "" : ", ") + c.first;
              throw InputError("option " + key + ": expected one of " + names);
            }
            access(o) = it->second;
          }};
}

using FP = FeaturePipelineOptions;
using TO = TrackerOptions;
using CO = calib::CalibrationOptions;
using DO = pipeline::CalibrateDatasetOptions;
using SC = sim::SimConfig;

// The tilt check's options of a job whose options hold `tilt` (pipeline::TiltCheckOptions).
template <class O>
OptionTable<O> tilt_options() {
  return {
      field<bool, O>(
          "tilt_check", "measure the tilt of the mirror axis before tracking", [](O & o) -> auto& {
            return o.tilt.enabled;
          }),
      field<double, O>(
          "tilt_correct_above", "rectify the frames above this tilt [deg]", [](O & o) -> auto& {
            return o.tilt.correct_deg;
          }),
      field<double, O>(
          "tilt_deg",
          "the tilt when known [deg]: rectified with it, not measured (0: measure)",
          [](O & o) -> auto& { return o.tilt.given_deg; }),
      field<double, O>(
          "tilt_direction_deg",
          "the camera bearing the given tilt leans towards [deg]",
          [](O & o) -> auto& { return o.tilt.given_direction_deg; }),
  };
}

// The tables `parts`, one after the other.
template <class O>
OptionTable<O> joined(std::initializer_list<OptionTable<O>> parts) {
  OptionTable<O> t;
  for (const OptionTable<O>& p : parts) t.insert(t.end(), p.begin(), p.end());
  return t;
}

}  // namespace

const OptionTable<FP>& extraction_table() {
  static const OptionTable<FP> t{
      choice<FP>(
          "line_threshold",
          "which lines to keep: significant-or-long, significance, fraction, adaptive or topk",
          [](FP & o) -> auto& { return o.lines.threshold; },
          std::map<std::string, LineThreshold>{
              {"significant-or-long", LineThreshold::kSignificantOrLong},
              {"significance", LineThreshold::kSignificance},
              {"fraction", LineThreshold::kFractionOfAnnulus},
              {"adaptive", LineThreshold::kAdaptive},
              {"topk", LineThreshold::kTopK}}),
      field<int, FP>(
          "peak_window",
          "sectors added on each side of a line peak's 0.5 degree sector",
          [](FP & o) -> auto& { return o.lines.peak_window; }),
      field<int, FP>(
          "nms_radius", "a peak beats this many sectors on each side", [](FP & o) -> auto& {
            return o.lines.nms_radius;
          }),
      field<double, FP>(
          "length_fraction", "line length threshold, fraction of the annulus", [](FP & o) -> auto& {
            return o.lines.length_fraction;
          }),
      field<double, FP>(
          "min_significance", "-log10 NFA of a line kept (significance)", [](FP & o) -> auto& {
            return o.lines.min_significance;
          }),
      field<double, FP>(
          "faint_min_significance",
          "-log10 NFA of a faint line kept when it covers faint_min_fraction",
          [](FP & o) -> auto& { return o.lines.faint_min_significance; }),
      field<double, FP>(
          "faint_min_fraction",
          "fraction of the annulus a faint line must cover",
          [](FP & o) -> auto& { return o.lines.faint_min_fraction; }),
      field<double, FP>(
          "faint_max_fit_px",
          "RMS distance of a faint line's support pixels from its line, px",
          [](FP & o) -> auto& { return o.lines.faint_max_fit_px; }),
      field<int, FP>(
          "top_k", "lines kept per frame (topk)", [](FP & o) -> auto& { return o.lines.top_k; }),
      field<double, FP>(
          "gradient_threshold", "Sobel magnitude of an edge pixel", [](FP & o) -> auto& {
            return o.lines.gradient_threshold;
          }),
      {"fixed_center",
       "keep the first frame's centre instead of detecting it on every frame",
       [](FP& o) { return py::cast(!o.track_center); },
       [](FP& o, const py::handle& v) { o.track_center = !v.cast<bool>(); }},
      field<bool, FP>(
          "refine_center",
          "fit the centre to the rim even when sensor.yaml gives it",
          [](FP & o) -> auto& { return o.refine_given_center; }),
      choice<FP>(
          "smoothing",
          "the Gaussian window as an image blur (blur) or a vote weight",
          [](FP & o) -> auto& { return o.descriptor.smoothing; },
          std::map<std::string, DescriptorSmoothing>{
              {"blur", DescriptorSmoothing::kGaussianBlur},
              {"weight", DescriptorSmoothing::kGaussianWeight}}),
      choice<FP>(
          "normalization",
          "normalisation unit: each left/right pair or each half",
          [](FP & o) -> auto& { return o.descriptor.normalization; },
          std::map<std::string, DescriptorNormalization>{
              {"pair", DescriptorNormalization::kPerPair},
              {"half", DescriptorNormalization::kPerHalf}}),
      field<int, FP>(
          "bins", "orientation bins per histogram", [](FP & o) -> auto& {
            return o.descriptor.bins;
          }),
      field<int, FP>(
          "areas", "circular areas per line: 3 or 5", [](FP & o) -> auto& {
            return o.descriptor.areas;
          }),
      field<double, FP>(
          "clip", "clipping threshold after unit normalisation", [](FP & o) -> auto& {
            return o.descriptor.clip;
          }),
  };
  return t;
}

const OptionTable<TO>& tracker_table() {
  static const OptionTable<TO> t{
      field<bool, TO>(
          "mutual", "one-to-one, mutual nearest neighbours", [](TO & o) -> auto& {
            return o.mutual;
          }),
      {"gate",
       "the odometry bearing gate (needs the wheel base)",
       [](TO& o) { return py::cast(o.gate.enabled); },
       [](TO& o, const py::handle& v) { o.gate.enabled = v.cast<bool>(); }},
      field<int, TO>(
          "look_back", "frames searched back for an unmatched line", [](TO & o) -> auto& {
            return o.look_back;
          }),
      field<double, TO>(
          "f1", "test 1, eq. (8): min distance <= f1", [](TO & o) -> auto& { return o.match.f1; }),
      field<double, TO>(
          "f2", "test 2, eq. (9): min <= f2 * mean", [](TO & o) -> auto& { return o.match.f2; }),
      field<double, TO>(
          "f3", "test 3, eq. (10): min <= f3 * second min", [](TO & o) -> auto& {
            return o.match.f3;
          }),
      field<double, TO>(
          "partial_area_scale",
          "occluder-tolerant descriptor distance: the two areas that agree decide "
          "where one holds more than (s-1)/s of the squared distance; 0: off",
          [](TO & o) -> auto& { return o.match.partial_area_scale; }),
      field<double, TO>(
          "partial_side_scale",
          "occluder-tolerant descriptor distance by sides: also s times the closer "
          "side's squared distance; 0: off",
          [](TO & o) -> auto& { return o.match.partial_side_scale; }),
      field<bool, TO>(
          "gate_candidates",
          "tests 1, 3 and mutual among the lines the gate admits",
          [](TO & o) -> auto& { return o.gate_candidates; }),
      field<bool, TO>(
          "same_polarity", "match only lines of the same edge polarity", [](TO & o) -> auto& {
            return o.same_polarity;
          }),
      degrees<TO>(
          "continuity", "track continuity tolerance [deg] (0: off)", [](TO & o) -> auto& {
            return o.continuity_tolerance;
          }),
      choice<TO>(
          "continuity_model",
          "track continuity prediction: link or track",
          [](TO & o) -> auto& { return o.continuity_model; },
          std::map<std::string, TO::ContinuityModel>{{"link", TO::ContinuityModel::kLink},
                                                     {"track", TO::ContinuityModel::kTrack}}),
      field<double, TO>(
          "continuity_path_curvature",
          "unpredicted change per metre^2 [rad/m^2]",
          [](TO & o) -> auto& { return o.continuity_path_curvature; }),
      field<double, TO>(
          "continuity_turn_curvature",
          "unpredicted change per radian^2 turned",
          [](TO & o) -> auto& { return o.continuity_turn_curvature; }),
      field<double, TO>(
          "look_back_f1", "test 1 across a look-back gap (0: f1)", [](TO & o) -> auto& {
            return o.look_back_f1;
          }),
      field<bool, TO>(
          "heads_only",
          "look-back links only to a track's latest observation",
          [](TO & o) -> auto& { return o.heads_only; }),
      field<double, TO>(
          "confirm_f1",
          "confirmed F1: larger distance the track's motion confirms",
          [](TO & o) -> auto& { return o.confirm_f1; }),
      degrees<TO>(
          "confirm_tolerance",
          "confirmed F1: deviation from the prediction [deg]",
          [](TO & o) -> auto& { return o.confirm_tolerance; }),
      field<bool, TO>(
          "triangulate",
          "predict a track's bearing from its line's triangulated position",
          [](TO & o) -> auto& { return o.triangulate; }),
      field<double, TO>(
          "predict_f1",
          "links by prediction: largest descriptor distance (0: off)",
          [](TO & o) -> auto& { return o.predict_f1; }),
      degrees<TO>(
          "camera_yaw",
          "the camera's yaw on the robot, phi + psi [deg] (NaN: estimated)",
          [](TO & o) -> auto& { return o.camera_yaw; }),
      {"gate_min_distance",
       "odometry gate: nearest line distance from the camera [m]",
       [](TO& o) { return py::cast(o.gate.min_feature_distance); },
       [](TO& o, const py::handle& v) { o.gate.min_feature_distance = v.cast<double>(); }},
      degrees<TO>(
          "gate_tolerance",
          "odometry gate: bearing detection tolerance [deg]",
          [](TO & o) -> auto& { return o.gate.bearing_tolerance; }),
  };
  return t;
}

const OptionTable<CO>& calibration_table() {
  static const OptionTable<CO> t{
      field<bool, CO>(
          "refine",
          "batch maximum-likelihood refinement over the whole run (Ceres)",
          [](CO & o) -> auto& { return o.refinement.enabled; }),
      field<double, CO>(
          "split_chi2", "split a slipped track at this statistic (0: off)", [](CO & o) -> auto& {
            return o.association.split_chi2;
          }),
      field<bool, CO>(
          "join", "join a new track to the lost line it continues", [](CO & o) -> auto& {
            return o.association.join_pieces;
          }),
      field<double, CO>(
          "join_prediction_sigmas",
          "filter: join only where the lost line's predicted bearing is this sharp [bearing "
          "sigmas]",
          [](CO & o) -> auto& { return o.association.join_prediction_sigmas; }),
      degrees<CO>(
          "crossing_guard",
          "leave out bearings within this of another line [deg]",
          [](CO & o) -> auto& { return o.association.crossing_guard; }),
      field<bool, CO>(
          "noise_check", "the data's check of the bearing noise", [](CO & o) -> auto& {
            return o.noise_check.enabled;
          }),
      field<double, CO>(
          "noise_check_lower_level",
          "level of the noise check's 'less noise' side",
          [](CO & o) -> auto& { return o.noise_check.lower_level; }),
      field<double, CO>(
          "phi", "prior phi [rad]", [](CO & o) -> auto& { return o.prior.mean.phi; }),
      field<double, CO>(
          "rho", "prior rho [m]", [](CO & o) -> auto& { return o.prior.mean.rho; }),
      field<double, CO>(
          "psi", "prior psi [rad]", [](CO & o) -> auto& { return o.prior.mean.psi; }),
      field<double, CO>(
          "sigma_phi", "prior sigma of phi [rad]", [](CO & o) -> auto& {
            return o.prior.sigma(0);
          }),
      field<double, CO>(
          "sigma_rho", "prior sigma of rho [m]", [](CO & o) -> auto& { return o.prior.sigma(1); }),
      field<double, CO>(
          "sigma_psi", "prior sigma of psi [rad]", [](CO & o) -> auto& {
            return o.prior.sigma(2);
          }),
      degrees<CO>(
          "bearing_sigma", "bearing noise sigma of eq. (30) [deg]", [](CO & o) -> auto& {
            return o.noise.bearing_sigma;
          }),
      degrees<CO>(
          "track_bias_sigma",
          "constant bearing error per track [deg] (0: none)",
          [](CO & o) -> auto& { return o.noise.track_bias_sigma; }),
      field<double, CO>(
          "odometry_inflation", "factor on the Chong-Kleeman K in the filter", [](CO & o) -> auto& {
            return o.filter.odometry_inflation;
          }),
      field<double, CO>(
          "lateral_sigma", "sideways slip per image step in the batches [m]", [](CO & o) -> auto& {
            return o.robot.lateral_sigma;
          }),
  };
  return t;
}

const OptionTable<CO>& robot_table() {
  static const OptionTable<CO> t{
      field<double, CO>(
          "wheel_base", "wheel base e of eq. (15) [m]", [](CO & o) -> auto& {
            return o.robot.wheel_base;
          }),
      field<double, CO>(
          "odometry_k", "Chong-Kleeman K of eq. (31) [m]", [](CO & o) -> auto& {
            return o.robot.odometry_K;
          }),
  };
  return t;
}

const OptionTable<DO>& dataset_job_table() {
  static const OptionTable<DO> t = joined<DO>(
      {OptionTable<DO>{
           field<bool, DO>(
               "force",
               "write extrinsics.yaml even when the run does not determine them",
               [](DO & o) -> auto& { return o.force; }),
           field<std::string, DO>(
               "tracks",
               "calibrate from this tracks.csv instead of the images",
               [](DO & o) -> auto& { return o.tracks_file; }),
           field<bool, DO>(
               "streaming",
               "frame by frame as the robot drives, nothing looked ahead (streaming.csv)",
               [](DO & o) -> auto& { return o.streaming; }),
           field<std::string, DO>(
               "mask", "image mask file instead of sensor.yaml's mask:", [](DO & o) -> auto& {
                 return o.mask;
               }),
           field<double, DO>(
               "crowded_sigma", "bearing sigma factor of a crowded line", [](DO & o) -> auto& {
                 return o.input.crowded_sigma_scale;
               }),
           field<double, DO>(
               "calibration_length_fraction",
               "lines shorter than this fraction of the annulus are tracked, not used",
               [](DO & o) -> auto& { return o.input.min_annulus_fraction; }),
           field<int, DO>(
               "calibration_enough_tracks",
               "fewer tracks with long lines than this: shorter lines are used (0: never)",
               [](DO & o) -> auto& { return o.input.enough_tracks; }),
           field<int, DO>(
               "split_after_short",
               "a track whose line was short this many frames is a new track after (0: never)",
               [](DO & o) -> auto& { return o.input.split_after_short; }),
           field<double, DO>(
               "max_wheel_gap", "wheel samples further apart are a gap [s]", [](DO & o) -> auto& {
                 return o.input.max_wheel_gap_s;
               }),
           {"time_offset",
            "camera-odometry time offset [s], or 'estimate'",
            [](DO& o) {
              return o.time_offset_s ? py::cast(*o.time_offset_s)
                                     : py::cast(std::string("estimate"));
            },
            [](DO& o, const py::handle& v) {
              if (py::isinstance<py::str>(v) && v.cast<std::string>() == "estimate")
                o.time_offset_s.reset();
              else
                o.time_offset_s = v.cast<double>();
            }},
       },
       tilt_options<DO>(),
       OptionTable<DO>{
           field<std::string, DO>(
               "base_frame", "the robot's frame in the robot-format files", [](DO & o) -> auto& {
                 return o.frames.base;
               }),
           field<std::string, DO>(
               "camera_frame", "the camera's frame in the robot-format files", [](DO & o) -> auto& {
                 return o.frames.camera;
               }),
           {"camera_height",
            "camera centre above the base frame [m] (None: 0 in the files)",
            [](DO& o) {
              return o.frames.camera_height ? py::cast(*o.frames.camera_height) : py::none();
            },
            [](DO& o, const py::handle& v) {
              o.frames.camera_height =
                  v.is_none() ? std::nullopt : std::optional<double>(v.cast<double>());
            }},
       }});
  return t;
}

const OptionTable<pipeline::TrackDatasetOptions>& track_job_table() {
  using TD = pipeline::TrackDatasetOptions;
  static const OptionTable<TD> t = joined<TD>({
      OptionTable<TD>{field<std::string, TD>(
          "mask", "image mask file instead of sensor.yaml's mask:", [](TD & o) -> auto& {
            return o.mask;
          })},
      tilt_options<TD>(),
  });
  return t;
}

const OptionTable<SC>& simulation_table() {
  static const OptionTable<SC> t{
      field<std::uint64_t, SC>(
          "seed", "seed of every random draw", [](SC & o) -> auto& { return o.seed; }),
      field<int, SC>(
          "frames", "at most this many frames (0: whole trajectory)", [](SC & o) -> auto& {
            return o.max_frames;
          }),
      field<double, SC>(
          "rate", "frame rate [Hz]", [](SC & o) -> auto& { return o.frame_rate; }),
      field<int, SC>(
          "width", "image width [px]", [](SC & o) -> auto& { return o.camera.width; }),
      field<int, SC>(
          "height", "image height [px]", [](SC & o) -> auto& { return o.camera.height; }),
      {"center",
       "mirror centre (cx, cy) [px]",
       [](SC& o) { return py::cast(std::make_pair(o.camera.cx, o.camera.cy)); },
       [](SC& o, const py::handle& v) {
         std::tie(o.camera.cx, o.camera.cy) = v.cast<std::pair<double, double>>();
       }},
      field<double, SC>(
          "xi", "unified model mirror parameter", [](SC & o) -> auto& { return o.camera.xi; }),
      field<double, SC>(
          "gamma", "unified model focal length [px]", [](SC & o) -> auto& {
            return o.camera.gamma;
          }),
      field<double, SC>(
          "r_min", "valid annulus inner radius [px]", [](SC & o) -> auto& {
            return o.camera.r_min;
          }),
      field<double, SC>(
          "r_max", "valid annulus outer radius [px]", [](SC & o) -> auto& {
            return o.camera.r_max;
          }),
      field<int, SC>(
          "bearing_sign", "+1: beta = a; -1: mirrored image", [](SC & o) -> auto& {
            return o.camera.bearing_sign;
          }),
      field<double, SC>(
          "tilt_deg", "tilt of the mirror axis [deg]", [](SC & o) -> auto& {
            return o.camera.tilt_deg;
          }),
      field<double, SC>(
          "tilt_direction_deg", "bearing the tilted axis leans towards [deg]", [](SC & o) -> auto& {
            return o.camera.tilt_direction_deg;
          }),
      field<double, SC>(
          "camera_height", "camera centre above the floor [m]", [](SC & o) -> auto& {
            return o.camera_height;
          }),
      field<double, SC>(
          "phi", "extrinsics phi [rad]", [](SC & o) -> auto& { return o.extrinsics.phi; }),
      field<double, SC>(
          "rho", "extrinsics rho [m]", [](SC & o) -> auto& { return o.extrinsics.rho; }),
      field<double, SC>(
          "psi", "extrinsics psi [rad]", [](SC & o) -> auto& { return o.extrinsics.psi; }),
      field<double, SC>(
          "wheel_rate", "wheel data rate [Hz]", [](SC & o) -> auto& { return o.wheel.rate_hz; }),
      field<double, SC>(
          "wheel_base", "nominal wheel base [m]", [](SC & o) -> auto& {
            return o.wheel.wheel_base;
          }),
      field<double, SC>(
          "odometry_k", "Chong-Kleeman K [m]", [](SC & o) -> auto& { return o.wheel.odometry_k; }),
      field<double, SC>(
          "radius_error_left", "systematic scale error of the left wheel", [](SC & o) -> auto& {
            return o.wheel.radius_error_left;
          }),
      field<double, SC>(
          "radius_error_right", "systematic scale error of the right wheel", [](SC & o) -> auto& {
            return o.wheel.radius_error_right;
          }),
      field<double, SC>(
          "wheel_base_error", "true wheel base = nominal * (1 + this)", [](SC & o) -> auto& {
            return o.wheel.wheel_base_error;
          }),
      field<double, SC>(
          "noise", "image noise sigma [grey levels]", [](SC & o) -> auto& {
            return o.image.noise_sigma;
          }),
      field<double, SC>(
          "gain_flicker", "per-frame gain sigma (relative)", [](SC & o) -> auto& {
            return o.image.gain_flicker;
          }),
      field<double, SC>(
          "exposure", "mean gain; > 1 saturates bright areas", [](SC & o) -> auto& {
            return o.image.exposure;
          }),
      field<double, SC>(
          "blur", "Gaussian blur sigma [px]", [](SC & o) -> auto& { return o.image.blur_sigma; }),
      field<bool, SC>(
          "write_mask", "write the ground-truth mask cam0/mask.png", [](SC & o) -> auto& {
            return o.overlay.write_mask;
          }),
  };
  return t;
}

TrackerOptions tracker_from_kwargs(py::dict& kwargs,
                                   double wheel_base,
                                   bool for_dataset,
                                   const char* call) {
  std::string rules = "recommended";
  if (kwargs.contains("rules")) {
    rules = kwargs["rules"].cast<std::string>();
    PyDict_DelItemString(kwargs.ptr(), "rules");
  }
  TrackerOptions o;
  if (rules == "paper") {
    o = paper_tracker_options();
    o.gate.wheel_base = wheel_base;
  } else if (rules == "recommended") {
    o = for_dataset ? recommended_dataset_tracker_options()
                    : recommended_tracker_options(wheel_base);
  } else {
    throw InputError("option rules: expected 'recommended' or 'paper', got '" + rules + "'");
  }
  apply_options(tracker_table(), o, kwargs, call);
  if (o.gate.enabled && !for_dataset && o.gate.wheel_base <= 0.0) o.gate.wheel_base = wheel_base;
  return o;
}

}  // namespace omnivert::python
