#include "omnivert/calib/track_ids.hpp"

#include <algorithm>
#include <iterator>

namespace omnivert::calib {

std::map<int, int> join_roots(const std::vector<TrackJoin>& joins) {
  std::map<int, int> earlier;  // joined piece -> the piece it continues
  auto root_of = [&earlier](int x) {
    for (auto it = earlier.find(x); it != earlier.end(); it = earlier.find(x)) x = it->second;
    return x;
  };
  // A piece's last join is the one kept (the pairs are taken from the last), and a join that
  // would close a loop is left out, so the chains end. The window reports its joins by the
  // tracker's ids, and two pieces of one tracker id (parted at a gap or a slip, then joined)
  // give (T, T), or T -> U -> T, a chain without end
  // (PiecesOfOneLine.JoinChainsEndAtTheFirstPiece). Where the pairs make no loop, every pair is
  // followed.
  for (auto it = joins.rbegin(); it != joins.rend(); ++it) {
    const auto& [a, c] = *it;
    if (a == c || earlier.count(c) || root_of(a) == c) continue;
    earlier[c] = a;
  }
  std::map<int, int> root;
  for (const auto& [c, a] : earlier) root[c] = root_of(a);
  return root;
}

CalibrationRun join_tracks(const CalibrationRun& run,
                           const std::vector<TrackJoin>& joins,
                           std::map<int, int>* renamed) {
  std::map<int, int> root = join_roots(joins);
  CalibrationRun out = run;
  for (FrameInput& f : out.frames)
    for (BearingObservation& o : f.observations)
      if (const auto it = root.find(o.track_id); it != root.end()) o.track_id = it->second;
  if (renamed) *renamed = std::move(root);
  return out;
}

CalibrationRun split_tracks(const CalibrationRun& run,
                            const std::vector<TrackSplit>& splits,
                            std::map<int, int>* origin) {
  if (origin) origin->clear();
  if (splits.empty()) return run;
  int next_id = 0;
  for (const FrameInput& f : run.frames)
    for (const BearingObservation& o : f.observations) next_id = std::max(next_id, o.track_id + 1);
  // Per track, its split frames in order, and the id of the part starting at each.
  std::map<int, std::map<int, int>> parts;
  for (const auto& [id, frame] : splits) parts[id].emplace(frame, 0);
  for (auto& [id, starts] : parts)
    for (auto& [frame, nid] : starts) {
      nid = next_id++;
      if (origin) (*origin)[nid] = id;
    }
  CalibrationRun out = run;
  for (std::size_t k = 0; k < out.frames.size(); ++k)
    for (BearingObservation& o : out.frames[k].observations) {
      const auto it = parts.find(o.track_id);
      if (it == parts.end()) continue;
      auto p = it->second.upper_bound(static_cast<int>(k));  // first split after frame k
      if (p == it->second.begin()) continue;                 // before the first split
      o.track_id = std::prev(p)->second;
    }
  return out;
}

}  // namespace omnivert::calib
