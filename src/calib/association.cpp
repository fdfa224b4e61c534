#include "calib/association.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <spdlog/spdlog.h>

#include "calib/updater.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/track_ids.hpp"

namespace omnivert::calib::internal {

CalibrationRun split_round(const CalibrationRun& original,
                           const CalibrationRun& current,
                           const std::vector<std::pair<int, int>>& found,
                           std::vector<TrackSplit>* splits,
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
                 const CalibrationOptions& options,
                 CalibrationRun* run,
                 BatchPoint* at,
                 std::vector<TrackJoin>* joins) {
  const std::vector<TrackJoin> found =
      find_merges(b,
                  options.association.max_missed_frames,
                  chi2_quantile(options.association.gate_probability, 2));
  if (found.empty()) return false;
  *at = point_of(*b);
  std::map<int, int> renamed;
  *run = join_tracks(*run, found, &renamed);
  for (const auto& [id, into] : renamed) at->features.erase(id);
  joins->insert(joins->end(), found.begin(), found.end());
  return true;
}

CalibrationOptions association_options(const CalibrationOptions& options) {
  CalibrationOptions a = options;
  a.noise.bearing_sigma = std::hypot(options.noise.bearing_sigma, options.noise.track_bias_sigma);
  a.noise.track_bias_sigma = 0.0;
  return a;
}

Built final_with_bias(const CalibrationRun& run,
                      const Built& b,
                      const CalibrationOptions& options,
                      bool robust,
                      int min_track_length) {
  const std::set<BearingKey> keep(b.bearing_keys.begin(), b.bearing_keys.end());
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
  CalibrationOptions o = options;
  o.association.min_track_length = min_track_length;
  Built f = build(kept, o, point_of(b), robust);
  f.guarded = b.guarded;
  return f;
}

std::map<int, int> tracker_ids(const std::map<int, int>& base, const std::map<int, int>& origin) {
  std::map<int, int> m = base;
  for (const auto& [id, o] : origin) m[id] = base.count(o) ? base.at(o) : o;
  return m;
}

void place_changed(const CalibrationRun& run,
                   const std::set<int>& changed,
                   const AssociationSetup& setup,
                   BatchPoint* at) {
  if (changed.empty()) return;
  CalibrationRun only = run;
  for (FrameInput& f : only.frames)
    std::erase_if(f.observations,
                  [&](const BearingObservation& o) { return !changed.count(o.track_id); });
  Built p = setup.rebuild(only, *at);
  if (p.features.empty()) return;
  for (auto& pose : p.poses)
    if (p.problem->HasParameterBlock(pose.data()))
      p.problem->SetParameterBlockConstant(pose.data());
  p.problem->SetParameterBlockConstant(p.ex.data());
  if (!p.time_offset.empty()) p.problem->SetParameterBlockConstant(p.time_offset.data());
  ceres::Solver::Summary summary;
  ceres::Solve(small_solver_options(), p.problem.get(), &summary);
  for (const auto& [id, f] : p.features)
    if (std::isfinite(f[0]) && std::isfinite(f[1])) at->features[id] = {f[0], f[1]};
}

namespace {

bool out_of_features(const Built& b, const AssociationSetup& setup) {
  return setup.stop_when_empty && b.features.empty();
}

// The crossing guard of the association's options (reject_crossings).
int guard_crossings(Built* b, const AssociationSetup& setup, const std::map<int, int>& tracker) {
  const AssociationOptions& a = setup.options->association;
  return reject_crossings(b,
                          a.crossing_guard,
                          a.max_missed_frames,
                          setup.min_bearings,
                          tracker,
                          chi2_quantile(a.gate_probability, 2));
}

// The outlier gate in sigmas: the filter's chi-square gate, 1 degree of freedom.
double outlier_gate(const AssociationSetup& setup) {
  return std::sqrt(chi2_quantile(setup.options->association.gate_probability, 1));
}

// The crossing guard, the features collapsed onto the camera, the outliers, each followed by
// a solve; `at_solution`: the problem's values are a solution without the bearings these
// judgements would remove (AssociationSetup::judge_before_solving), so the three are judged
// there together and solved once, then the outliers again. *rejected: the outliers. false: no
// feature left (AssociationSetup::stop_when_empty).
bool reject_and_solve(Built* b,
                      const AssociationSetup& setup,
                      const std::map<int, int>& tracker,
                      int* rejected,
                      bool at_solution = false) {
  const CalibrationOptions& options = *setup.options;
  bool pending = at_solution;  // a solve is owed (every bearing back in)
  // Bearings where lines cross out first (the outliers are judged without them).
  if (guard_crossings(b, setup, tracker) > 0) {
    if (out_of_features(*b, setup)) return false;
    if (!at_solution) setup.solve(b);
  }
  *rejected = 0;
  if (drop_collapsed_features(b, options.association.min_feature_range) > 0) {
    if (out_of_features(*b, setup)) return false;
    if (!at_solution) setup.solve(b);
  }
  const double gate = outlier_gate(setup);
  for (int round = 0; round < 3; ++round) {
    const int n = reject_outliers(b, gate, setup.min_bearings);
    *rejected += n;
    if (n == 0) break;
    setup.solve(b);
    pending = false;
  }
  if (pending && !out_of_features(*b, setup)) setup.solve(b);
  return !out_of_features(*b, setup);
}

// The tracks of `next` that a round joined or split: those whose bearings are not exactly the
// bearings of one track of `previous` (split_tracks and join_tracks only rename: observation i
// of frame k is the same bearing in both runs).
std::set<int> changed_tracks(const CalibrationRun& previous, const CalibrationRun& next) {
  std::map<int, std::set<int>> sources;  // track of next -> tracks of previous
  std::map<int, int> size_next, size_previous;
  for (std::size_t k = 0; k < next.frames.size(); ++k) {
    const auto& a = next.frames[k].observations;
    const auto* c = k < previous.frames.size() ? &previous.frames[k].observations : nullptr;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ++size_next[a[i].track_id];
      sources[a[i].track_id].insert(c && i < c->size() ? (*c)[i].track_id : -1);
    }
  }
  for (const FrameInput& f : previous.frames)
    for (const BearingObservation& o : f.observations) ++size_previous[o.track_id];
  std::set<int> changed;
  for (const auto& [id, from] : sources) {
    const int source = *from.begin();
    if (from.size() != 1 || source < 0 || size_previous[source] != size_next[id])
      changed.insert(id);
  }
  return changed;
}

// The problem of the renamed run `run` (renamed from `previous`) from `at`, solved, and
// judged again; with AssociationSetup::judge_before_solving, judged before its first solve,
// at `at` with the points of the tracks the round joined or split placed (place_changed).
AssociationEnd rebuild_and_judge(Built* b,
                                 const CalibrationRun& previous,
                                 const CalibrationRun& run,
                                 const BatchPoint& at,
                                 const AssociationSetup& setup,
                                 Association* out) {
  const std::map<int, int> tracker = tracker_ids(setup.base_origin, out->origin);
  // `at` is the last solution: the tracks the round left as they were are at their points.
  // Judged before solving, the joined and split ones are placed from their own bearings and
  // every bearing is judged there, all tracks together (crossings, collapsed points,
  // outliers); otherwise the problem is solved first with every bearing in.
  BatchPoint start = at;
  if (setup.judge_before_solving) place_changed(run, changed_tracks(previous, run), setup, &start);
  // The old problem goes before the new one is built (on a long run each holds hundreds of MB).
  *b = Built{};
  *b = setup.rebuild(run, start);
  if (out_of_features(*b, setup)) return AssociationEnd::kNoTrack;
  if (!setup.judge_before_solving) setup.solve(b);
  if (!reject_and_solve(
          b, setup, tracker, &out->num_rejected, /*at_solution=*/setup.judge_before_solving))
    return AssociationEnd::kNoTrackLeft;
  return AssociationEnd::kDone;
}

}  // namespace

AssociationEnd associate(Built* b,
                         const CalibrationRun& run,
                         const AssociationSetup& setup,
                         Association* out) {
  out->merged = run;
  if (!reject_and_solve(b, setup, tracker_ids(setup.base_origin, out->origin), &out->num_rejected))
    return AssociationEnd::kNoTrackLeft;
  // Pieces of one line joined (the tracker lost the line and found it again under a new id),
  // each line starting at its first piece's point.
  for (int round = 0; setup.join_pieces && round < kMergeRounds; ++round) {
    BatchPoint at;
    const std::size_t before = out->merges.size();
    const CalibrationRun previous = out->merged;
    if (setup.progress)
      setup.progress("refinement: joining pieces", static_cast<std::size_t>(round) + 1, 0);
    if (!merge_round(b, *setup.options, &out->merged, &at, &out->merges)) break;
    spdlog::debug(
        "association: round {} joined {} pairs of pieces", round + 1, out->merges.size() - before);
    if (const AssociationEnd end = rebuild_and_judge(b, previous, out->merged, at, setup, out);
        end != AssociationEnd::kDone)
      return end;
  }
  // Tracks that slipped onto a neighbouring line split in two, from the current solution (all
  // bearings back in, outliers judged again).
  for (int round = 0; setup.split.split_chi2 > 0.0 && round < setup.split.split_rounds; ++round) {
    if (setup.progress)
      setup.progress("refinement: splitting tracks", static_cast<std::size_t>(round) + 1, 0);
    const std::vector<std::pair<int, int>> found = find_splits(*b, setup.split);
    if (found.empty()) break;
    spdlog::debug("association: round {} split tracks at {} frames", round + 1, found.size());
    BatchPoint at = point_of(*b);
    const CalibrationRun previous = round == 0 ? out->merged : out->split;
    out->split = split_round(
        out->merged, round == 0 ? out->merged : out->split, found, &out->splits, &out->origin, &at);
    out->num_splits += static_cast<int>(found.size());
    if (const AssociationEnd end = rebuild_and_judge(b, previous, out->split, at, setup, out);
        end != AssociationEnd::kDone)
      return end;
  }
  return AssociationEnd::kDone;
}

}  // namespace omnivert::calib::internal
