#include "omnivert/pipeline/track_dataset.hpp"

#include <set>
#include <string>

#include "omnivert/core/error.hpp"
#include "pipeline/frame_source.hpp"

namespace omnivert::pipeline {

TrackDatasetResult track_dataset(const dataset::Dataset& data,
                                 const TrackDatasetOptions& options,
                                 const std::function<void(std::size_t, std::size_t)>& progress,
                                 bool keep_features) {
  const std::string csv = data.root() + "/cam0/data.csv";
  if (data.size() == 0) throw InputError(csv, 0, "the dataset has no images");
  TrackerOptions to = options.tracker;
  const bool odometry = options.use_odometry && data.has_wheel();
  if (to.gate.enabled) {
    if (odometry) {
      to.gate.wheel_base = data.wheel_sensor().wheel_base;
    } else {
      to.gate.enabled = false;  // no wheel data: no gate
    }
  }
  Tracker tracker(to);
  CameraGeometry camera = data.camera();
  if (!options.mask.empty()) camera.mask = options.mask;
  TrackDatasetResult out;
  FeaturePipelineOptions po = options.pipeline;
  if (po.tilt.isZero()) {
    const TiltChoice c =
        choose_tilt(options.tilt, [&] { return measure_tilt(data, po, options.tilt); });
    out.tilt = c.tilt;
    out.tilt_corrected = c.rectified;
    if (c.rectified) po.tilt = c.tilt.vector;
    if (!c.warning.empty()) out.warnings.push_back(c.warning);
  }
  FeaturePipeline pipe(camera, po);
  FrameSource frames(data, pipe, options.threads);
  FrameFeatures f;
  std::vector<TrackAssignment> assignments;
  const auto& travel = data.travel_at_images();
  const std::size_t n = data.size();
  for (std::size_t i = 0; i < n; ++i) {
    const FrameSource::Frame& fr = frames.next();
    for (const std::string& w : fr.warnings) out.warnings.push_back(w);
    if (fr.ok) {
      f = fr.features;
    } else {
      // Skipped: no lines, the previous circle (the tracker and the rows need only lines).
      ++out.frames_skipped;
      f.lines.clear();
      f.descriptors.resize(0, options.pipeline.descriptor.size());
    }
    if (odometry && to.gate.enabled) {
      const WheelIncrement inc =
          i == 0 ? WheelIncrement{}
                 : increment_between(
                       travel[i - 1].left, travel[i - 1].right, travel[i].left, travel[i].right);
      tracker.add_frame(f, inc, &assignments);
    } else {
      tracker.add_frame(f, &assignments);
    }
    append_track_rows(
        static_cast<std::int64_t>(i), data.images()[i].timestamp_ns, f, assignments, &out.rows);
    if (keep_features) out.features.push_back(f);
    ++out.frames;
    if (progress) progress(i + 1, n);
  }
  if (out.frames_skipped == out.frames) {
    throw InputError(csv,
                     0,
                     "no frame could be processed (" +
                         (out.warnings.empty() ? std::string("?") : out.warnings.front()) + ")");
  }
  out.stats = tracker.stats();
  return out;
}

TrackDatasetResult read_tracks_for_dataset(const std::string& file, const dataset::Dataset& data) {
  TrackDatasetResult t;
  t.rows = read_tracks_csv(file);
  const auto& images = data.images();
  std::set<std::int64_t> ids;
  for (const TrackRow& r : t.rows) {
    const int line = r.source_line;
    if (r.frame >= static_cast<std::int64_t>(images.size()))
      throw InputError(file,
                       line,
                       "frame " + std::to_string(r.frame) + " is not an image of " + data.root() +
                           " (it has " + std::to_string(images.size()) + ")");
    const auto& im = images[static_cast<std::size_t>(r.frame)];
    if (r.timestamp_ns != im.timestamp_ns)
      throw InputError(file,
                       line,
                       "frame " + std::to_string(r.frame) + " has timestamp " +
                           std::to_string(r.timestamp_ns) + " but cam0/data.csv line " +
                           std::to_string(im.line) + " has " + std::to_string(im.timestamp_ns) +
                           ": these tracks are not of this dataset");
    ids.insert(r.track_id);
  }
  t.frames = static_cast<std::int64_t>(images.size());
  t.stats.new_tracks = static_cast<std::int64_t>(ids.size());
  return t;
}

}  // namespace omnivert::pipeline
