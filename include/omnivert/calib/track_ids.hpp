#pragma once
// Renaming a run's tracks: parts of a track split where it slipped onto a neighbouring line,
// pieces of one line joined under one id.

#include <map>
#include <utility>
#include <vector>

#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// The run with tracks split at the given (tracker's track id, first frame of the new part)
// pairs (RefinementResult::splits, FilterResult::splits): each part between consecutive split
// frames of a track gets a new id, from one above the largest id of the run. `origin`
// (optional) receives new id -> tracker's id.
CalibrationRun split_tracks(const CalibrationRun& run,
                            const std::vector<TrackSplit>& splits,
                            std::map<int, int>* origin = nullptr);

// The run with pieces of one line under one id (RefinementResult::merges,
// FilterResult::joins: pairs (earlier piece's id, joined piece's id)): each joined piece takes
// the id of its line's first piece (chains followed). `renamed` (optional) receives each
// renamed id -> its new id.
CalibrationRun join_tracks(const CalibrationRun& run,
                           const std::vector<TrackJoin>& joins,
                           std::map<int, int>* renamed = nullptr);
// Each joined piece's line: joined piece's id -> the id of its line's first piece (chains of
// (earlier, later) pairs followed to their start). What join_tracks renames by. Of several
// pairs for one piece the last counts; a pair that joins a piece to itself or would close a
// loop is left out: every chain ends.
std::map<int, int> join_roots(const std::vector<TrackJoin>& joins);

}  // namespace omnivert::calib
