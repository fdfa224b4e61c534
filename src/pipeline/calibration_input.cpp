#include "omnivert/pipeline/calibration_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::pipeline {

bool DatasetRunOptions::IsValid(std::string* why) const {
  const auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(std::isfinite(max_wheel_gap_s) && max_wheel_gap_s > 0.0))
    return fail("max_wheel_gap_s must be > 0 [s]");
  if (min_lines < 1) return fail("min_lines must be >= 1");
  if (!(std::isfinite(max_starved_s) && max_starved_s > 0.0))
    return fail("max_starved_s must be > 0 [s]");
  if (min_track_length < 2) return fail("min_track_length must be >= 2");
  if (!(std::isfinite(crowded_sigma_scale) && crowded_sigma_scale > 0.0))
    return fail("crowded_sigma_scale must be > 0");
  if (!(min_annulus_fraction >= 0.0 && min_annulus_fraction <= 1.0))
    return fail("min_annulus_fraction must be in [0, 1]");
  if (enough_tracks < 0) return fail("enough_tracks must be >= 0");
  if (split_after_short < 0) return fail("split_after_short must be >= 0");
  if (!(std::isfinite(short_sigma_scale) && short_sigma_scale > 0.0))
    return fail("short_sigma_scale must be > 0");
  return true;
}

namespace {

std::string wheel_csv(const dataset::Dataset& d) { return d.root() + "/wheel0/data.csv"; }

// Index of the last wheel sample at or before t (the wheel data covers every image: the
// dataset reader checks it).
std::size_t sample_before(const std::vector<dataset::WheelRecord>& w, std::int64_t t) {
  auto it =
      std::upper_bound(w.begin(), w.end(), t, [](std::int64_t v, const dataset::WheelRecord& r) {
        return v < r.timestamp_ns;
      });
  return it == w.begin() ? 0 : static_cast<std::size_t>(it - w.begin()) - 1;
}

}  // namespace

std::vector<Eigen::Vector2d> wheel_travel_between_images(const dataset::Dataset& data,
                                                         std::size_t i) {
  const auto& travel = data.travel_at_images();
  const auto& wheel = data.wheel();
  // On the odometry clock: the stamps shifted by the camera-odometry time offset.
  const std::int64_t t0 = data.odometry_time(i - 1), t1 = data.odometry_time(i);
  std::vector<Eigen::Vector2d> steps(1, Eigen::Vector2d(travel[i - 1].left, travel[i - 1].right));
  for (std::size_t k = sample_before(wheel, t0) + 1; k < wheel.size() && wheel[k].timestamp_ns < t1;
       ++k)
    if (wheel[k].timestamp_ns > t0) steps.emplace_back(wheel[k].travel.left, wheel[k].travel.right);
  steps.emplace_back(travel[i].left, travel[i].right);
  return steps;
}

std::shared_ptr<const calib::WheelClock> wheel_clock(const dataset::Dataset& data) {
  auto c = std::make_shared<calib::WheelClock>();
  const auto& wheel = data.wheel();
  if (wheel.empty()) return c;
  const std::int64_t t0 = wheel.front().timestamp_ns;
  for (const auto& w : wheel) {
    c->t.push_back(static_cast<double>(w.timestamp_ns - t0) * 1e-9);
    c->left.push_back(w.travel.left);
    c->right.push_back(w.travel.right);
  }
  for (std::size_t i = 0; i < data.images().size(); ++i)
    c->image_t.push_back(static_cast<double>(data.odometry_time(i) - t0) * 1e-9);
  return c;
}

namespace {

// Wheel travel per frame (eq. 14-15's inputs), and the heading for the motion summary.
void add_frame_motion(const dataset::Dataset& data, DatasetRun& out) {
  const auto& images = data.images();
  const auto& travel = data.travel_at_images();
  const std::size_t n = images.size();
  // Every wheel sample between two images is used: eq. (14) per sample, composed
  // (compose_wheel_steps), so that a frame in which the robot ends a straight and starts to
  // turn moves it as it moved. (Eq. 14 once over such a frame puts the robot 0.47 mm to the
  // side of where it went, simulator's paper trajectory, frame 61; the batch allows 0.01 mm
  // of side slip per frame, and the 0.47 mm went into rho: -0.3 mm of bias over 50 runs in
  // both worlds, docs/theory/filter.md#each-frames-motion-from-its-wheel-samples.)
  const double e = data.wheel_sensor().wheel_base;
  std::vector<Eigen::Vector2d> steps;
  for (std::size_t i = 1; i < n; ++i) {
    calib::FrameInput& f = out.run.frames[i];
    steps = wheel_travel_between_images(data, i);
    if (e > 0) {
      const Eigen::Vector3d m = calib::compose_wheel_steps(steps, e, &f.covariance_per_K);
      f.d_right = m(0);
      f.d_left = m(1);
      f.lateral = m(2);
    } else {
      f.d_left = travel[i].left - travel[i - 1].left;
      f.d_right = travel[i].right - travel[i - 1].right;
    }
    out.path_length += std::abs(0.5 * (f.d_left + f.d_right));
    if (e > 0) out.rotation += std::abs((f.d_right - f.d_left) / e);
  }
}

// Wheel gaps: an image whose bracketing wheel samples are further apart than the limit.
// Returns, per frame, whether its bearings are left out.
std::vector<char> wheel_gaps(const dataset::Dataset& data,
                             const DatasetRunOptions& opt,
                             DatasetRun& out) {
  const auto& images = data.images();
  const auto& wheel = data.wheel();
  const std::size_t n = images.size();
  std::vector<char> gap(n, 0);
  {
    int gap_first = -1, gap_last = -1;
    std::size_t gap_sample = 0;
    auto flush = [&]() {
      if (gap_first < 0) return;
      const auto& a = wheel[gap_sample];
      const auto& b = wheel[std::min(gap_sample + 1, wheel.size() - 1)];
      char buf[400];
      std::snprintf(buf,
                    sizeof buf,
                    "%s: lines %d-%d: no wheel sample for %.3g s (limit %.3g s); the bearings "
                    "of frames %d-%d (cam0/data.csv lines %d-%d) are not used, their poses "
                    "being unknown; the travel across the gap is kept",
                    wheel_csv(data).c_str(),
                    a.line,
                    b.line,
                    static_cast<double>(b.timestamp_ns - a.timestamp_ns) * 1e-9,
                    opt.max_wheel_gap_s,
                    gap_first,
                    gap_last,
                    images[gap_first].line,
                    images[gap_last].line);
      out.warnings.emplace_back(buf);
      gap_first = gap_last = -1;
    };
    for (std::size_t i = 0; i < n; ++i) {
      // An image outside the wheel data (after a time offset: Dataset::set_image_time_offset)
      // has no known pose either; the caller warns about those.
      if (data.image_outside_wheel_data(i)) {
        gap[i] = 1;
        ++out.frames_dropped_for_gaps;
        flush();
        continue;
      }
      const std::size_t k = sample_before(wheel, data.odometry_time(i));
      bool is_gap = false;
      if (wheel[k].timestamp_ns != data.odometry_time(i) && k + 1 < wheel.size()) {
        const double dt =
            static_cast<double>(wheel[k + 1].timestamp_ns - wheel[k].timestamp_ns) * 1e-9;
        is_gap = dt > opt.max_wheel_gap_s;
      }
      if (is_gap) {
        gap[i] = 1;
        ++out.frames_dropped_for_gaps;
        if (gap_first >= 0 && k != gap_sample) flush();
        if (gap_first < 0) {
          gap_first = static_cast<int>(i);
          gap_sample = k;
        }
        gap_last = static_cast<int>(i);
      } else {
        flush();
      }
    }
    flush();
  }

  return gap;
}

// The calibration's id of each row: its track id, except that where a track's long lines
// resume after at least `split_after` short ones the rest of it is a new track (ids above
// every track id, in the order they start). A track whose line was short for a while may
// have slipped onto another edge meanwhile: the tracker followed it by lines whose bearings
// the calibration does not check; a line that dips below the fraction for a single frame
// (one about half the annulus long) keeps its track. Rows in frame order within a track
// (tracks.csv's order; others are sorted).
std::vector<std::int64_t> pieces_between_short_lines(
    const std::vector<TrackRow>& rows,
    const std::function<bool(const TrackRow&)>& is_short,
    int split_after) {
  std::vector<std::size_t> order(rows.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return rows[a].frame < rows[b].frame;
  });
  std::int64_t next = 0;
  for (const TrackRow& r : rows) next = std::max(next, r.track_id + 1);
  struct State {
    std::int64_t piece = -1;
    int short_since_long = 0;
  };
  std::map<std::int64_t, State> state;
  std::vector<std::int64_t> id(rows.size());
  for (std::size_t i : order) {
    State& st = state[rows[i].track_id];
    if (st.piece < 0) st.piece = rows[i].track_id;
    if (is_short(rows[i])) {
      ++st.short_since_long;
    } else {
      if (split_after > 0 && st.short_since_long >= split_after) st.piece = next++;
      st.short_since_long = 0;
    }
    id[i] = st.piece;
  }
  return id;
}

// The fraction of the annulus a line must cover for its bearing to be used:
// options.min_annulus_fraction when at least options.enough_tracks tracks hold that many lines
// of it, else the first of 0.35, 0.25 and 0 (every line) below it that gives as many, else the
// one that gives the most tracks.
double choose_annulus_fraction(const std::vector<TrackRow>& rows,
                               const DatasetRunOptions& opt,
                               DatasetRun& out) {
  const double preferred = opt.min_annulus_fraction;
  if (opt.enough_tracks <= 0 || preferred <= 0.0) return preferred;
  auto tracks_at = [&](double f) {
    auto is_short = [f](const TrackRow& r) { return r.annulus_fraction < f; };  // NaN: used
    const std::vector<std::int64_t> id =
        pieces_between_short_lines(rows, is_short, opt.split_after_short);
    std::map<std::int64_t, int> length;
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (!is_short(rows[i])) ++length[id[i]];
    int tracks = 0;
    for (const auto& [id, k] : length) tracks += k >= opt.min_track_length ? 1 : 0;
    return tracks;
  };
  const int at_preferred = tracks_at(preferred);
  if (at_preferred >= opt.enough_tracks) return preferred;
  double best = preferred;
  int best_tracks = at_preferred;
  for (double f : {0.35, 0.25, 0.0}) {
    if (f >= preferred) continue;
    const int t = tracks_at(f);
    if (t > best_tracks) best = f, best_tracks = t;
    if (t >= opt.enough_tracks) break;
  }
  if (best != preferred) {
    char text[320];
    std::snprintf(text,
                  sizeof(text),
                  "only %d tracks hold lines at least %g of the annulus long; the bearings of "
                  "lines at least %g of it are used (%d tracks): shorter lines' bearings are less "
                  "accurate (docs/calibration.md#which-lines)",
                  at_preferred,
                  preferred,
                  best,
                  best_tracks);
    out.warnings.emplace_back(text);
  }
  return best;
}

// Track lengths (short tracks carry no parallax) and double claims; the bearings used.
void add_bearings(const std::vector<TrackRow>& rows,
                  const std::vector<char>& gap,
                  const DatasetRunOptions& opt,
                  DatasetRun& out) {
  const std::size_t n = out.run.frames.size();
  for (const TrackRow& r : rows)
    if (r.frame < 0 || static_cast<std::size_t>(r.frame) >= n)
      throw InputError("tracks: frame " + std::to_string(r.frame) + " outside the dataset's " +
                       std::to_string(n) + " images");
  const double min_fraction = choose_annulus_fraction(rows, opt, out);
  // A line shorter than min_fraction is tracked, not used (its track's length counts the
  // bearings used only).
  auto too_short = [&](const TrackRow& r) { return r.annulus_fraction < min_fraction; };
  const std::vector<std::int64_t> id =
      pieces_between_short_lines(rows, too_short, opt.split_after_short);
  std::map<std::int64_t, int> length;
  std::map<std::pair<std::int64_t, std::int64_t>, int> per_frame;  // (frame, piece) -> count
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ++per_frame[{rows[i].frame, id[i]}];
    if (too_short(rows[i])) {
      ++out.short_bearings;
      continue;
    }
    ++length[id[i]];
  }
  std::map<std::int64_t, int> used_tracks;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const TrackRow& r = rows[i];
    if (too_short(r) || length[id[i]] < opt.min_track_length) continue;
    if (gap[static_cast<std::size_t>(r.frame)]) continue;
    if (!std::isfinite(r.bearing)) continue;
    if (per_frame[{r.frame, id[i]}] > 1) {
      ++out.double_claims;
      continue;
    }
    // Shorter than the preferred fraction (used because too few tracks hold long lines):
    // noisier, and partly the same from frame to frame (DatasetRunOptions).
    const double shorter =
        r.annulus_fraction < opt.min_annulus_fraction ? opt.short_sigma_scale : 1.0;
    out.run.frames[static_cast<std::size_t>(r.frame)].observations.push_back(
        {static_cast<int>(id[i]),
         r.bearing,
         (r.crowded ? opt.crowded_sigma_scale : 1.0) * shorter});
    ++used_tracks[id[i]];
    ++out.observations;
    out.crowded_bearings += r.crowded ? 1 : 0;
  }
  out.tracks = static_cast<int>(used_tracks.size());
  out.crowded_sigma_scale = opt.crowded_sigma_scale;
  out.min_annulus_fraction = min_fraction;
  out.split_after_short = opt.split_after_short;
  if (out.double_claims > 0) {
    out.warnings.push_back(std::to_string(out.double_claims) +
                           " times a track held two lines of one frame (the paper's rules allow "
                           "it); those bearings were not used (the recommended rules prevent it)");
  }
}

// Starved stretches: too few lines for too long (a warning); no frame with lines at all is
// an InputError.
void check_starved(const dataset::Dataset& data, const DatasetRunOptions& opt, DatasetRun& out) {
  const auto& images = data.images();
  const std::size_t n = images.size();
  int starved_first = -1, frames_with_lines = 0;
  auto starved_flush = [&](std::size_t end) {  // [starved_first, end)
    if (starved_first < 0) return;
    const double dt =
        static_cast<double>(images[end - 1].timestamp_ns - images[starved_first].timestamp_ns) *
        1e-9;
    if (dt > opt.max_starved_s) {
      char buf[300];
      std::snprintf(buf,
                    sizeof buf,
                    "frames %d-%zu (cam0/data.csv lines %d-%d, %.1f s): fewer than %d tracked "
                    "lines; the filter dead-reckons through them and the extrinsics learn "
                    "nothing there",
                    starved_first,
                    end - 1,
                    images[starved_first].line,
                    images[end - 1].line,
                    dt,
                    opt.min_lines);
      out.warnings.emplace_back(buf);
    }
    starved_first = -1;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (static_cast<int>(out.run.frames[i].observations.size()) < opt.min_lines) {
      ++out.starved_frames;
      if (starved_first < 0) starved_first = static_cast<int>(i);
    } else {
      ++frames_with_lines;
      starved_flush(i);
    }
  }
  starved_flush(n);
  if (frames_with_lines == 0) {
    throw InputError(data.root(),
                     0,
                     "no frame has " + std::to_string(opt.min_lines) +
                         " or more tracked lines: nothing to calibrate from (check the images "
                         "with `omnivert extract`, or the annulus in cam0/sensor.yaml)");
  }
}

}  // namespace

DatasetRun calibration_run_from_tracks(const dataset::Dataset& data,
                                       const std::vector<TrackRow>& rows,
                                       const DatasetRunOptions& opt) {
  if (!data.has_wheel())
    throw InputError(data.root() + "/wheel0",
                     0,
                     "calibration needs wheel odometry (wheel0/data.csv and wheel0/sensor.yaml)");
  DatasetRun out;
  out.run.frames.resize(data.images().size());
  add_frame_motion(data, out);
  const std::vector<char> gap = wheel_gaps(data, opt, out);
  add_bearings(rows, gap, opt, out);
  check_starved(data, opt, out);
  return out;
}

calib::CalibrationOptions options_from_dataset(const dataset::Dataset& data,
                                               calib::CalibrationOptions base) {
  if (data.has_wheel()) {
    base.robot.wheel_base = data.wheel_sensor().wheel_base;
    if (data.wheel_sensor().odometry_k) base.robot.odometry_K = *data.wheel_sensor().odometry_k;
  }
  return base;
}

}  // namespace omnivert::pipeline
