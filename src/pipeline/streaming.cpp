#include "omnivert/pipeline/streaming.hpp"

#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/match/odometry_gate.hpp"

namespace omnivert::pipeline {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace

bool StreamingOptions::IsValid(std::string* why) const {
  std::string w;
  const auto fail = [&](const char* group) {
    if (why) *why = std::string(group) + " options: " + w;
    return false;
  };
  if (!features.IsValid(&w)) return fail("extraction");
  TrackerOptions t = tracker;
  if (t.gate.enabled && t.gate.wheel_base == 0.0) t.gate.wheel_base = 1.0;  // the calibrator's
  if (!t.IsValid(&w)) return fail("tracker");
  if (!calibration.IsValid(&w)) return fail("calibration");
  if (!input.IsValid(&w)) return fail("input");
  return true;
}

struct StreamingCalibrator::Impl {
  Impl(const CameraGeometry& camera, double wheel_base, const StreamingOptions& o)
      : options(o),
        pipe(camera, o.features),
        tracker(tracker_options(o.tracker, wheel_base)),
        filter(filter_options(o.calibration, wheel_base)),
        wheel_base(wheel_base) {}

  static TrackerOptions tracker_options(TrackerOptions t, double e) {
    if (t.gate.enabled) t.gate.wheel_base = e;
    return t;
  }
  static calib::CalibrationOptions filter_options(calib::CalibrationOptions c, double e) {
    c.robot.wheel_base = e;
    return c;
  }

  // The filter's input of the frame: the wheel travel (eq. 14-15, every sample composed:
  // calib::compose_wheel_steps) and the bearings of the lines that are long enough, each
  // under its track's current piece (DatasetRunOptions::split_after_short). A track that
  // holds two lines of the frame gives neither (the batch input's double claims).
  void make_input(const std::vector<Eigen::Vector2d>& travel) {
    input = calib::FrameInput{};
    if (travel.size() >= 2) {
      const Eigen::Vector3d m =
          calib::compose_wheel_steps(travel, wheel_base, &input.covariance_per_K);
      input.d_right = m(0);
      input.d_left = m(1);
      input.lateral = m(2);
    }
    const DatasetRunOptions& in = options.input;
    std::map<int, int> count;  // piece -> bearings in this frame
    std::vector<std::pair<int, const TrackRow*>> used;
    for (const TrackRow& r : rows) {
      Piece& p = pieces[r.track_id];
      if (p.id < 0) p.id = static_cast<int>(r.track_id);
      if (r.annulus_fraction < in.min_annulus_fraction) {
        ++p.short_since_long;
        ++short_bearings;
        continue;
      }
      if (in.split_after_short > 0 && p.short_since_long >= in.split_after_short)
        p.id = next_piece++;
      p.short_since_long = 0;
      if (!std::isfinite(r.bearing)) continue;
      ++count[p.id];
      used.emplace_back(p.id, &r);
    }
    for (const auto& [id, r] : used) {
      if (count[id] > 1) continue;
      input.observations.push_back({id, r->bearing, r->crowded ? in.crowded_sigma_scale : 1.0});
    }
  }

  struct Piece {
    int id = -1;
    int short_since_long = 0;
  };

  StreamingOptions options;
  FeaturePipeline pipe;
  Tracker tracker;
  calib::CalibrationFilter filter;
  double wheel_base;
  FrameFeatures features;
  std::vector<TrackAssignment> assignments;
  std::vector<TrackRow> rows;
  calib::FrameInput input;
  std::map<std::int64_t, Piece> pieces;  // tracker's id -> its current piece
  int next_piece = kFirstPieceId;
  int short_bearings = 0;
  std::int64_t frame = 0;
};

StreamingCalibrator::StreamingCalibrator(const CameraGeometry& camera,
                                         double wheel_base,
                                         const StreamingOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("invalid " + why);
  if (!(std::isfinite(wheel_base) && wheel_base > 0.0))
    throw InputError("streaming calibration: the wheel base must be > 0 [m], got " +
                     std::to_string(wheel_base));
  impl_ = std::make_unique<Impl>(camera, wheel_base, options);
}

StreamingCalibrator::~StreamingCalibrator() = default;

StreamingEstimate StreamingCalibrator::add_frame(std::int64_t timestamp_ns,
                                                 const cv::Mat& image,
                                                 const std::vector<Eigen::Vector2d>& wheel_travel) {
  Impl& m = *impl_;
  for (const Eigen::Vector2d& t : wheel_travel)
    if (!t.allFinite())
      throw InputError("streaming calibration: frame " + std::to_string(m.frame) +
                       ": non-finite wheel travel");
  StreamingEstimate e;
  e.frame = m.frame;
  e.timestamp_ns = timestamp_ns;
  auto t0 = Clock::now();
  try {
    e.described = !image.empty() && m.pipe.process(image, m.features, &e.problem);
    if (image.empty()) e.problem = "no image";
  } catch (const InputError& x) {
    e.described = false;
    e.problem = x.what();
  }
  if (!e.described) {
    m.features.lines.clear();
    m.features.descriptors.resize(0, m.options.features.descriptor.size());
  }
  e.front_end_ms = ms_since(t0);
  e.lines = static_cast<int>(m.features.lines.size());

  t0 = Clock::now();
  if (m.options.tracker.gate.enabled) {
    WheelIncrement inc;  // none before the first frame
    if (wheel_travel.size() >= 2) {
      const Eigen::Vector2d& a = wheel_travel.front();
      const Eigen::Vector2d& b = wheel_travel.back();
      inc = increment_between(a(0), a(1), b(0), b(1));
    }
    m.tracker.add_frame(m.features, inc, &m.assignments);
  } else {
    m.tracker.add_frame(m.features, &m.assignments);
  }
  m.rows.clear();
  append_track_rows(m.frame, timestamp_ns, m.features, m.assignments, &m.rows);
  e.tracker_ms = ms_since(t0);

  t0 = Clock::now();
  m.make_input(wheel_travel);
  m.filter.process(m.input);
  e.filter_ms = ms_since(t0);
  e.bearings = static_cast<int>(m.input.observations.size());
  e.bootstrapping = m.filter.bootstrapping();
  e.extrinsics = m.filter.extrinsics();
  e.covariance = m.filter.covariance();
  e.features = m.filter.num_features();
  ++m.frame;
  return e;
}

void StreamingCalibrator::finish() { impl_->filter.finish(); }

const calib::CalibrationFilter& StreamingCalibrator::filter() const { return impl_->filter; }
const TrackerStats& StreamingCalibrator::tracker_stats() const { return impl_->tracker.stats(); }
const std::vector<TrackRow>& StreamingCalibrator::last_rows() const { return impl_->rows; }
const calib::FrameInput& StreamingCalibrator::last_input() const { return impl_->input; }
int StreamingCalibrator::short_bearings() const { return impl_->short_bearings; }

}  // namespace omnivert::pipeline
