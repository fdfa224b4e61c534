#include "calib/association.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "omnivert/calib/track_ids.hpp"
#include "omnivert/calib/updater.hpp"

namespace omnivert::calib::internal {

CalibrationRun split_round(const CalibrationRun& original,
                           const CalibrationRun& current,
                           const std::map<int, int>& found,
                           std::vector<std::pair<int, int>>* splits,
                           std::map<int, int>* origin,
                           BatchPoint* at) {
  for (const auto& [id, frame] : found) {
    const auto it = origin->find(id);
    splits->emplace_back(it != origin->end() ? it->second : id, frame);
  }
  std::map<int, int> next_origin;
  CalibrationRun next = split_tracks(original, *splits, &next_origin);
  // split_tracks only renames: observation i of frame k is the same bearing in both runs.
  std::map<int, Eigen::Vector2d> features;
  for (std::size_t k = 0; k < next.frames.size() && k < current.frames.size(); ++k) {
    const auto& a = next.frames[k].observations;
    const auto& c = current.frames[k].observations;
    for (std::size_t i = 0; i < a.size() && i < c.size(); ++i) {
      if (features.count(a[i].track_id)) continue;
      const auto f = at->features.find(c[i].track_id);
      if (f != at->features.end()) features[a[i].track_id] = f->second;
    }
  }
  at->features = std::move(features);
  *origin = std::move(next_origin);
  return next;
}

bool merge_round(Built* b,
                 const Options& options,
                 CalibrationRun* run,
                 BatchPoint* at,
                 std::vector<std::pair<int, int>>* joins) {
  const std::vector<std::pair<int, int>> found =
      find_merges(b, options.max_missed_frames, chi2_quantile(options.gate_probability, 2));
  if (found.empty()) return false;
  *at = point_of(*b);
  std::map<int, int> renamed;
  *run = join_tracks(*run, found, &renamed);
  for (const auto& [id, into] : renamed) at->features.erase(id);
  joins->insert(joins->end(), found.begin(), found.end());
  return true;
}

Options association_options(const Options& options) {
  Options a = options;
  a.bearing_sigma = std::hypot(options.bearing_sigma, options.track_bias_sigma);
  a.track_bias_sigma = 0.0;
  return a;
}

Built final_with_bias(const CalibrationRun& run,
                      const Built& b,
                      const Options& options,
                      const BatchOptions& batch,
                      bool robust,
                      int min_track_length) {
  const std::set<std::pair<int, int>> keep(b.bearing_keys.begin(), b.bearing_keys.end());
  CalibrationRun kept = run;
  for (std::size_t k = 0; k < kept.frames.size(); ++k) {
    auto& obs = kept.frames[k].observations;
    obs.erase(std::remove_if(obs.begin(),
                             obs.end(),
                             [&](const BearingObservation& o) {
                               return !keep.count({o.track_id, static_cast<int>(k)});
                             }),
              obs.end());
  }
  Options o = options;
  o.min_track_length = min_track_length;
  Built f = build(kept, o, point_of(b), batch, robust);
  f.guarded = b.guarded;
  return f;
}

}  // namespace omnivert::calib::internal
