#include "omnivert/eval/tracking_eval.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <unordered_map>

#include "omnivert/core/error.hpp"

namespace omnivert::eval {

bool TrackingEvalOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!(association_tolerance > 0.0 && association_tolerance < kPi)) {
    return fail("association tolerance must be in (0, pi) radians");
  }
  if (look_back < 1) return fail("look-back must be at least 1 frame");
  if (interval < 1) return fail("interval must be at least 1 frame");
  if (!(std::isfinite(annulus_r_min) && std::isfinite(annulus_r_max) && annulus_r_min >= 0.0 &&
        annulus_r_max > annulus_r_min)) {
    return fail("the annulus needs 0 <= R_min < R_max (pixels)");
  }
  if (!(long_line_fraction > 0.0 && long_line_fraction <= 1.0)) {
    return fail("long-line fraction must be in (0, 1]");
  }
  return true;
}

namespace {

void add(TrackingCounts* into, const TrackingCounts& c) {
  into->matches += c.matches;
  into->correct += c.correct;
  into->false_matches += c.false_matches;
  into->unverified += c.unverified;
  into->new_entries += c.new_entries;
  into->false_new_entries += c.false_new_entries;
}

}  // namespace

namespace {

// The number of frames of the dataset: given, or the largest frame index seen plus one.
std::int64_t count_frames(const std::vector<TrackRow>& tracks,
                          const std::vector<GroundTruthLine>& ground_truth,
                          const TrackingEvalOptions& options) {
  std::int64_t num_frames = options.num_frames;
  if (num_frames <= 0) {
    for (const TrackRow& r : tracks) num_frames = std::max(num_frames, r.frame + 1);
    for (const GroundTruthLine& g : ground_truth) num_frames = std::max(num_frames, g.frame + 1);
  }
  return num_frames;
}

// Rule 1: each detection's world line (the nearest true bearing within the tolerance).
struct Association {
  std::vector<std::int64_t> line;  // per detection, -1 when unassociated
  // Every world line within the tolerance (sorted ids): more than one when true lines are
  // closer than the tolerance (crossings, lines far ahead), where the nearest is noise.
  std::vector<std::vector<std::int64_t>> within;
  std::vector<char> gt_detected;  // per ground-truth row
  std::vector<char> occluder;     // per detection: on an occluder's side (rule 9)
};

// Rule 1 and rule 7 (bearing RMS).
Association associate_detections(const std::vector<TrackRow>& tracks,
                                 const std::vector<GroundTruthLine>& ground_truth,
                                 const std::vector<OccluderBearing>& occluders,
                                 const TrackingEvalOptions& options,
                                 TrackingEvaluation& ev) {
  std::unordered_map<std::int64_t, std::vector<double>> occluders_by_frame;
  for (const OccluderBearing& o : occluders) occluders_by_frame[o.frame].push_back(o.bearing);
  // Ground truth by frame.
  std::unordered_map<std::int64_t, std::vector<std::size_t>> gt_by_frame;
  for (std::size_t k = 0; k < ground_truth.size(); ++k) {
    gt_by_frame[ground_truth[k].frame].push_back(k);
  }
  const std::size_t n = tracks.size();
  Association a;
  a.line.assign(n, -1);
  a.within.resize(n);
  a.gt_detected.assign(ground_truth.size(), 0);
  a.occluder.assign(n, 0);
  double sq_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    // Rule 9: the nearest occluder side within the tolerance, if nearer than every true line.
    double occluder_d = options.association_tolerance;
    bool near_occluder = false;
    if (const auto o = occluders_by_frame.find(tracks[i].frame); o != occluders_by_frame.end()) {
      for (double b : o->second) {
        const double d = std::abs(angle_diff(tracks[i].bearing, b));
        if (d <= occluder_d) occluder_d = d, near_occluder = true;
      }
    }
    const auto it = gt_by_frame.find(tracks[i].frame);
    double best = options.association_tolerance;
    std::size_t best_k = ground_truth.size();
    std::vector<std::int64_t>& within = a.within[i];
    static const std::vector<std::size_t> kNone;
    for (std::size_t k : it == gt_by_frame.end() ? kNone : it->second) {
      const double d = std::abs(angle_diff(tracks[i].bearing, ground_truth[k].bearing));
      if (d <= options.association_tolerance) within.push_back(ground_truth[k].line_id);
      if (d <= best) {
        best = d;
        best_k = k;
      }
    }
    if (near_occluder && (best_k == ground_truth.size() || occluder_d < best)) {
      a.occluder[i] = 1;
      within.clear();
      ++ev.occluder_detections;
      continue;
    }
    std::sort(within.begin(), within.end());
    within.erase(std::unique(within.begin(), within.end()), within.end());
    if (within.size() > 1) ++ev.ambiguous_detections;
    if (best_k == ground_truth.size()) continue;
    a.line[i] = ground_truth[best_k].line_id;
    a.gt_detected[best_k] = 1;
    ++ev.associated_detections;
    const double e = angle_diff(tracks[i].bearing, ground_truth[best_k].bearing);
    sq_sum += e * e;
  }
  ev.detections = static_cast<std::int64_t>(n);
  ev.bearing_rms =
      ev.associated_detections > 0 ? std::sqrt(sq_sum / ev.associated_detections) : 0.0;
  return a;
}

// Rule 6: recall of long lines.
void count_long_lines(const std::vector<GroundTruthLine>& ground_truth,
                      const std::vector<char>& gt_detected,
                      const TrackingEvalOptions& options,
                      TrackingEvaluation& ev) {
  const double long_min =
      options.long_line_fraction * (options.annulus_r_max - options.annulus_r_min);
  for (std::size_t k = 0; k < ground_truth.size(); ++k) {
    if (ground_truth[k].r_outer - ground_truth[k].r_inner >= long_min) {
      ++ev.long_lines;
      ev.long_lines_detected += gt_detected[k];
    }
  }
}

// World lines detected per frame (sorted), for rule 4.
class DetectedLines {
 public:
  DetectedLines(const std::vector<TrackRow>& tracks, const std::vector<std::int64_t>& assoc) {
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      if (assoc[i] >= 0) by_frame_[tracks[i].frame].push_back(assoc[i]);
    }
    for (auto& [f, v] : by_frame_) std::sort(v.begin(), v.end());
  }
  bool contains(std::int64_t frame, std::int64_t line) const {
    const auto it = by_frame_.find(frame);
    return it != by_frame_.end() && std::binary_search(it->second.begin(), it->second.end(), line);
  }

 private:
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> by_frame_;
};

// Rule 5: the rows of the table, intervals of `interval` frames.
void make_intervals(std::int64_t num_frames,
                    const TrackingEvalOptions& options,
                    TrackingEvaluation& ev) {
  const std::int64_t num_intervals =
      std::max<std::int64_t>(1, (num_frames + options.interval - 1) / options.interval);
  ev.intervals.resize(static_cast<std::size_t>(num_intervals));
  for (std::int64_t k = 0; k < num_intervals; ++k) {
    auto& c = ev.intervals[static_cast<std::size_t>(k)];
    c.first_frame = k * options.interval;
    c.end_frame =
        std::min<std::int64_t>((k + 1) * options.interval, std::max<std::int64_t>(num_frames, 1));
  }
}

TrackingCounts& interval_of(TrackingEvaluation& ev,
                            const TrackingEvalOptions& options,
                            std::int64_t frame) {
  const auto num_intervals = static_cast<std::int64_t>(ev.intervals.size());
  const std::int64_t k = std::clamp<std::int64_t>(frame / options.interval, 0, num_intervals - 1);
  return ev.intervals[static_cast<std::size_t>(k)];
}

// Rule 2: the predecessor of detection dets[k] of a track (dets in frame order): its
// detection at matched_frame when known, else at the latest earlier frame.
std::size_t find_predecessor(const std::vector<TrackRow>& tracks,
                             const std::vector<std::size_t>& dets,
                             std::size_t k) {
  const std::size_t n = tracks.size();
  const TrackRow& d = tracks[dets[k]];
  std::int64_t pred_frame = -1;
  if (d.matched_frame >= 0) {
    for (std::size_t m = 0; m < k; ++m) {
      if (tracks[dets[m]].frame == d.matched_frame) pred_frame = d.matched_frame;
    }
  }
  if (pred_frame < 0) {
    for (std::size_t m = k; m-- > 0;) {
      if (tracks[dets[m]].frame < d.frame) {
        pred_frame = tracks[dets[m]].frame;
        break;
      }
    }
  }
  // The exact predecessor when the file names the matched line (matched_line); else, if
  // the track holds several lines in pred_frame (a double claim), the nearest bearing. That
  // guess goes wrong when the scene turns faster than the two lines are apart, so files
  // written by omnivert carry matched_line.
  std::size_t pred = n;
  if (d.matched_line >= 0 && pred_frame == d.matched_frame) {
    for (std::size_t m = 0; m < k; ++m) {
      const std::size_t j = dets[m];
      if (tracks[j].frame == pred_frame && tracks[j].line == d.matched_line) pred = j;
    }
  }
  double pred_d = 10.0;
  const bool exact = pred < n;
  for (std::size_t m = 0; m < k && !exact; ++m) {
    const std::size_t j = dets[m];
    if (tracks[j].frame != pred_frame) continue;
    const double dd = std::abs(angle_diff(tracks[j].bearing, d.bearing));
    if (dd < pred_d) {
      pred_d = dd;
      pred = j;
    }
  }
  assert(pred < n);
  return pred;
}

// Rules 2-4 along the links of one track (dets: its detections, sorted here in frame
// order): new entries and false new entries, and each link correct, false or unverified by
// the identity sets carried along the track.
void evaluate_track(const std::vector<TrackRow>& tracks,
                    std::vector<std::size_t>& dets,
                    const Association& assoc,
                    const DetectedLines& detected,
                    const TrackingEvalOptions& options,
                    std::vector<std::vector<std::int64_t>>& identity,
                    TrackingEvaluation& ev) {
  std::stable_sort(dets.begin(), dets.end(), [&](std::size_t a, std::size_t b) {
    return tracks[a].frame < tracks[b].frame;
  });
  const std::int64_t start_frame = tracks[dets.front()].frame;
  std::vector<std::int64_t> common;
  for (std::size_t k = 0; k < dets.size(); ++k) {
    const std::size_t i = dets[k];
    const TrackRow& d = tracks[i];
    const std::vector<std::int64_t>& within = assoc.within[i];
    if (k > 0 && tracks[dets[k - 1]].frame == d.frame) ++ev.duplicate_ids;
    if (assoc.occluder[i]) {  // rule 9: neither a new entry nor a link
      if (d.frame == start_frame) {
        ++ev.occluder_new_tracks;
      } else {
        ++ev.occluder_links;
      }
      continue;
    }
    if (d.frame == start_frame) {
      identity[i] = within;
      // Rule 2: the first detection(s) of a track id are new entries. Rule 4.
      TrackingCounts& c = interval_of(ev, options, d.frame);
      ++c.new_entries;
      if (assoc.line[i] >= 0) {
        for (int b = 1; b <= options.look_back; ++b) {
          if (detected.contains(d.frame - b, assoc.line[i])) {
            ++c.false_new_entries;
            break;
          }
        }
      }
      continue;
    }
    const std::size_t pred = find_predecessor(tracks, dets, k);
    if (assoc.occluder[pred]) {  // rule 9: a link from an occluder's side is left out
      ++ev.occluder_links;
      identity[i] = within;
      continue;
    }
    // Rule 3.
    TrackingCounts& c = interval_of(ev, options, d.frame);
    ++c.matches;
    if (within.empty() || identity[pred].empty()) {
      ++c.unverified;
      identity[i] = within;
      continue;
    }
    common.clear();
    std::set_intersection(identity[pred].begin(),
                          identity[pred].end(),
                          within.begin(),
                          within.end(),
                          std::back_inserter(common));
    if (!common.empty()) {
      ++c.correct;
      identity[i] = common;
    } else {
      ++c.false_matches;
      identity[i] = within;
    }
  }
}

// Rule 8: track purity. Per track, the world line most of its associated detections belong
// to; the associated detections on any other line follow a wrong line (a slip between two
// close lines counts one false match, but every detection after it here).
std::int64_t count_off_majority(const std::map<std::int64_t, std::vector<std::size_t>>& by_track,
                                const std::vector<std::int64_t>& assoc) {
  std::int64_t off = 0;
  for (const auto& [id, dets] : by_track) {
    std::map<std::int64_t, std::int64_t> count;
    std::int64_t associated = 0, majority = 0;
    for (std::size_t i : dets)
      if (assoc[i] >= 0) {
        ++associated;
        majority = std::max(majority, ++count[assoc[i]]);
      }
    off += associated - majority;
  }
  return off;
}

}  // namespace

TrackingEvaluation evaluate_tracking(const std::vector<TrackRow>& tracks,
                                     const std::vector<GroundTruthLine>& ground_truth,
                                     const TrackingEvalOptions& options,
                                     const std::vector<OccluderBearing>& occluders) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("evaluation options: " + error);
  TrackingEvaluation ev;
  const std::int64_t num_frames = count_frames(tracks, ground_truth, options);
  const Association assoc = associate_detections(tracks, ground_truth, occluders, options, ev);
  count_long_lines(ground_truth, assoc.gt_detected, options, ev);
  const DetectedLines detected(tracks, assoc.line);

  // Tracks: detections by id, in frame order.
  std::map<std::int64_t, std::vector<std::size_t>> by_track;
  for (std::size_t i = 0; i < tracks.size(); ++i) by_track[tracks[i].track_id].push_back(i);
  make_intervals(num_frames, options, ev);
  // Rule 3: identity sets propagated along the links of each track.
  std::vector<std::vector<std::int64_t>> identity(tracks.size());
  for (auto& [id, dets] : by_track) {
    evaluate_track(tracks, dets, assoc, detected, options, identity, ev);
  }
  ev.off_majority_detections += count_off_majority(by_track, assoc.line);
  ev.total.first_frame = 0;
  ev.total.end_frame = std::max<std::int64_t>(num_frames, 1);
  for (const auto& c : ev.intervals) add(&ev.total, c);
  return ev;
}

std::string format_tracking_table(const TrackingEvaluation& ev, const std::string& title) {
  std::string s = title + "\n";
  char buf[256];
  std::snprintf(buf,
                sizeof(buf),
                "%-16s %9s %10s %10s %11s %12s\n",
                "Frame interval",
                "Matches",
                "Correct %",
                "False m. %",
                "False new %",
                "Unverified %");
  s += buf;
  auto row = [&](const std::string& label, const TrackingCounts& c) {
    std::snprintf(buf,
                  sizeof(buf),
                  "%-16s %9lld %10.2f %10.2f %11.2f %12.2f\n",
                  label.c_str(),
                  static_cast<long long>(c.matches),
                  c.percent_correct(),
                  c.percent_false_matches(),
                  c.percent_false_new_entries(),
                  c.percent_unverified());
    s += buf;
  };
  for (const auto& c : ev.intervals) {
    row(std::to_string(c.first_frame) + "-" + std::to_string(c.end_frame), c);
  }
  row("Total", ev.total);
  std::snprintf(buf,
                sizeof(buf),
                "False matches: %lld, false new entries: %lld (of %lld new tracks)\n",
                static_cast<long long>(ev.total.false_matches),
                static_cast<long long>(ev.total.false_new_entries),
                static_cast<long long>(ev.total.new_entries));
  s += buf;
  std::snprintf(buf,
                sizeof(buf),
                "Detections: %lld, associated within tolerance: %lld (%.1f%%), ambiguous "
                "(several true lines within tolerance): %lld, duplicate ids in a frame: %lld\n",
                static_cast<long long>(ev.detections),
                static_cast<long long>(ev.associated_detections),
                ev.detections > 0 ? 100.0 * ev.associated_detections / ev.detections : 0.0,
                static_cast<long long>(ev.ambiguous_detections),
                static_cast<long long>(ev.duplicate_ids));
  s += buf;
  std::snprintf(buf,
                sizeof(buf),
                "Detections off their track's majority world line: %lld (%.2f%% of associated)\n",
                static_cast<long long>(ev.off_majority_detections),
                ev.associated_detections > 0
                    ? 100.0 * ev.off_majority_detections / ev.associated_detections
                    : 0.0);
  s += buf;
  if (ev.occluder_detections > 0) {
    std::snprintf(buf,
                  sizeof(buf),
                  "Detections on an occluder's side (left out): %lld, with %lld links and %lld "
                  "new tracks\n",
                  static_cast<long long>(ev.occluder_detections),
                  static_cast<long long>(ev.occluder_links),
                  static_cast<long long>(ev.occluder_new_tracks));
    s += buf;
  }
  std::snprintf(buf,
                sizeof(buf),
                "Recall of long lines: %.2f%% (%lld of %lld)\nBearing RMS error: %.3f deg\n",
                100.0 * ev.long_line_recall(),
                static_cast<long long>(ev.long_lines_detected),
                static_cast<long long>(ev.long_lines),
                rad2deg(ev.bearing_rms));
  s += buf;
  return s;
}

}  // namespace omnivert::eval
