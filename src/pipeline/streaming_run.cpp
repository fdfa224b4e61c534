#include "pipeline/streaming_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"
#include "omnivert/pipeline/tilt_check.hpp"

namespace omnivert::pipeline::internal {

namespace {

// The median, 95th percentile and largest of a series (nearest rank; 0 for none).
struct Spread {
  double median = 0.0, p95 = 0.0, max = 0.0;
};

Spread spread_of(std::vector<double> v) {
  Spread s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    const std::size_t k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
    return v[std::min(v.size(), std::max<std::size_t>(k, 1)) - 1];
  };
  s.median = at(0.5), s.p95 = at(0.95), s.max = v.back();
  return s;
}

// What the three reports say of a run's times: the frame whose filter step solved the
// start-up window (-1: none) and its time, and the spread of each stage's time per frame
// (the window's frame left out of the whole frame's and the filter's: it is reported alone).
struct Times {
  std::size_t frames = 0;
  std::int64_t window = -1;
  double window_ms = 0.0;
  Spread all, front_end, tracker, filter;
};

Times times_of(const std::vector<StreamingEstimate>& e) {
  Times t;
  t.frames = e.size();
  for (std::size_t i = 1; i < e.size() && t.window < 0; ++i)
    if (e[i - 1].bootstrapping && !e[i].bootstrapping) {
      t.window = e[i].frame;
      t.window_ms = e[i].latency_ms();
    }
  std::vector<double> all, front_end, tracker, filter;
  for (const StreamingEstimate& s : e) {
    front_end.push_back(s.front_end_ms);
    tracker.push_back(s.tracker_ms);
    if (s.frame == t.window) continue;
    all.push_back(s.latency_ms());
    filter.push_back(s.filter_ms);
  }
  t.all = spread_of(std::move(all));
  t.front_end = spread_of(std::move(front_end));
  t.tracker = spread_of(std::move(tracker));
  t.filter = spread_of(std::move(filter));
  return t;
}

}  // namespace

StreamedRun stream_dataset(const dataset::Dataset& data,
                           const CalibrateDatasetOptions& o,
                           const calib::CalibrationOptions& opt) {
  const std::string csv = data.root() + "/cam0/data.csv";
  if (data.size() == 0) throw InputError(csv, 0, "the dataset has no images");
  StreamingOptions so;
  so.features = o.features;
  so.tracker = o.tracker;
  so.calibration = opt;
  so.input = o.input;
  CameraGeometry camera = data.camera();
  if (!o.mask.empty()) camera.mask = o.mask;
  StreamedRun s;
  // The tilt (docs/theory/tilt.md): given, or measured on the first image alone (nothing is
  // looked ahead).
  if (so.features.tilt.isZero()) {
    const TiltChoice c = choose_tilt(o.tilt, [&] {
      try {
        return measure_image_tilt(data.image(0), camera, so.features, o.tilt);
      } catch (const InputError&) {
        return TiltEstimate{};  // unreadable: not measured (the loop below reports the frame)
      }
    });
    s.tracked.tilt = c.tilt;
    s.tracked.tilt_corrected = c.rectified;
    if (c.rectified) so.features.tilt = c.tilt.vector;
    if (!c.warning.empty()) s.tracked.warnings.push_back(c.warning);
  }
  StreamingCalibrator cal(camera, data.wheel_sensor().wheel_base, so);
  const std::size_t n = data.size();
  s.input.run.frames.reserve(n);
  s.estimates.reserve(n);
  const auto& travel = data.travel_at_images();
  std::set<int> tracks;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& im = data.images()[i];
    cv::Mat image;
    std::string why;
    try {
      image = data.image(i);
    } catch (const InputError& e) {
      why = e.what();
    }
    const std::vector<Eigen::Vector2d> wheel =
        i == 0 ? std::vector<Eigen::Vector2d>{Eigen::Vector2d(travel[0].left, travel[0].right)}
               : wheel_travel_between_images(data, i);
    StreamingEstimate e = cal.add_frame(im.timestamp_ns, image, wheel);
    if (!e.described) {
      ++s.tracked.frames_skipped;
      s.tracked.warnings.push_back((why.empty() ? im.path + ": " + e.problem : why) + "; frame " +
                                   std::to_string(i) + " skipped");
    }
    const auto& rows = cal.last_rows();
    s.tracked.rows.insert(s.tracked.rows.end(), rows.begin(), rows.end());
    const calib::FrameInput& f = cal.last_input();
    s.input.run.frames.push_back(f);
    s.input.observations += static_cast<int>(f.observations.size());
    for (const auto& b : f.observations) tracks.insert(b.track_id);
    s.input.path_length += std::abs(0.5 * (f.d_left + f.d_right));
    s.input.rotation += std::abs((f.d_right - f.d_left) / data.wheel_sensor().wheel_base);
    s.estimates.push_back(e);
    ++s.tracked.frames;
    if (o.progress) o.progress("stream", i + 1, n);
  }
  if (s.tracked.frames_skipped == s.tracked.frames)
    throw InputError(csv, 0, "no frame could be processed (" + s.tracked.warnings.front() + ")");
  cal.finish();
  const calib::CalibrationFilter& f = cal.filter();
  s.filter.extrinsics = f.extrinsics();
  s.filter.covariance = f.covariance();
  s.filter.history = f.history();
  s.filter.tracks = f.tracks();
  s.filter.splits = f.splits();
  s.filter.window_frames = f.window_frames();
  s.filter.window_failure = f.window_failure();
  s.filter.guarded = f.guarded();
  s.filter.rejected = f.rejected();
  s.filter.joins = f.joins();
  s.tracked.stats = cal.tracker_stats();
  s.input.tracks = static_cast<int>(tracks.size());
  s.input.short_bearings = cal.short_bearings();
  s.input.min_annulus_fraction = o.input.min_annulus_fraction;
  s.input.crowded_sigma_scale = o.input.crowded_sigma_scale;
  return s;
}

void write_streaming_csv(const std::string& path, const std::vector<StreamingEstimate>& estimates) {
  std::ostringstream s;
  s << "frame,timestamp_ns,state,phi,rho,psi,sigma_phi,sigma_rho,sigma_psi,lines,bearings,"
       "features,front_end_ms,tracker_ms,filter_ms,latency_ms\n";
  char buf[512];
  for (const StreamingEstimate& e : estimates) {
    const Eigen::Vector3d sd = e.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    std::snprintf(buf,
                  sizeof buf,
                  "%lld,%lld,%s,%.10g,%.10g,%.10g,%.6g,%.6g,%.6g,%d,%d,%d,%.4f,%.4f,%.4f,%.4f\n",
                  static_cast<long long>(e.frame),
                  static_cast<long long>(e.timestamp_ns),
                  e.bootstrapping ? "window" : "filter",
                  e.extrinsics.phi,
                  e.extrinsics.rho,
                  e.extrinsics.psi,
                  sd(0),
                  sd(1),
                  sd(2),
                  e.lines,
                  e.bearings,
                  e.features,
                  e.front_end_ms,
                  e.tracker_ms,
                  e.filter_ms,
                  e.latency_ms());
    s << buf;
  }
  write_text_atomic(path, s.str());
}

std::string streaming_json(const std::vector<StreamingEstimate>& estimates) {
  const Times t = times_of(estimates);
  auto json = [](const Spread& v) {
    return nlohmann::json{{"median", v.median}, {"p95", v.p95}, {"max", v.max}};
  };
  nlohmann::json j;
  j["frames"] = t.frames;
  j["window_solved_at_frame"] = t.window;
  j["window_ms"] = t.window_ms;
  j["latency_ms"] = json(t.all);
  j["front_end_ms"] = json(t.front_end);
  j["tracker_ms"] = json(t.tracker);
  j["filter_ms"] = json(t.filter);
  return j.dump();
}

std::string streaming_line(const std::vector<StreamingEstimate>& estimates) {
  const Times t = times_of(estimates);
  char buf[400];
  std::snprintf(buf,
                sizeof buf,
                "streaming: %zu frames, %.2f ms per frame (median; 95%%: %.2f, largest %.2f), of "
                "which the filter %.2f ms",
                t.frames,
                t.all.median,
                t.all.p95,
                t.all.max,
                t.filter.median);
  std::string s = buf;
  if (t.window >= 0) {
    std::snprintf(buf,
                  sizeof buf,
                  "; start-up window solved at frame %lld in %.1f ms",
                  static_cast<long long>(t.window),
                  t.window_ms);
    s += buf;
  }
  return s + "; streaming.csv";
}

std::string streaming_html(const std::vector<StreamingEstimate>& estimates) {
  const Times t = times_of(estimates);
  std::ostringstream h;
  char buf[600];
  h << "<h2>Streaming</h2>\n<p>Each frame went through extraction, tracker and filter as it "
       "came, on one thread, nothing looked ahead (streaming.csv has the estimate after every "
       "frame).";
  if (t.window >= 0) {
    std::snprintf(buf,
                  sizeof buf,
                  " The start-up window was solved at frame %lld (%.1f ms).",
                  static_cast<long long>(t.window),
                  t.window_ms);
    h << buf;
  }
  std::snprintf(buf,
                sizeof buf,
                "</p>\n<table><tr><th>per frame [ms]</th><th>median</th><th>95%%</th><th>largest"
                "</th></tr>\n<tr><td>in all</td><td>%.2f</td><td>%.2f</td><td>%.2f</td></tr>\n"
                "<tr><td>filter</td><td>%.2f</td><td>%.2f</td><td>%.2f</td></tr></table>\n",
                t.all.median,
                t.all.p95,
                t.all.max,
                t.filter.median,
                t.filter.p95,
                t.filter.max);
  h << buf;
  return h.str();
}

}  // namespace omnivert::pipeline::internal
