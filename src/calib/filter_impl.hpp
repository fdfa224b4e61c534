#pragma once
// The inside of CalibrationFilter (calibration_filter.hpp): the EKF state of eq. (28), its
// models (propagation eq. 29 and 31, update eq. 30, feature initialisation), the start-up
// window and the association bookkeeping.

#include <map>
#include <string>
#include <vector>

#include "calib/feature_initializer.hpp"
#include "calib/filter_state.hpp"
#include "calib/propagator.hpp"
#include "calib/updater.hpp"
#include "omnivert/calib/calibration_filter.hpp"

namespace omnivert::calib {

struct CalibrationFilter::Impl {
  explicit Impl(const CalibrationOptions& options);
  // CalibrationFilter::process and finish.
  void process(const FrameInput& frame);
  void finish();
  void admit(const FrameInput& frame);
  // One frame of the EKF (after the window): prediction, updates, new tracks, conversions,
  // marginalisation.
  void step(const FrameInput& frame);
  // The crossing guard in this frame: per entry (the state's features, then the frame's new
  // tracks at n + their index in the frame) whether it is left out.
  std::vector<char> crossing_entries(const FrameInput& frame) const;
  // The frame's bearings sorted: guarded (counted in rec), new tracks (*fresh), updates of
  // features of the state (*z, their own track ids *z_ids), a feature's second bearing
  // refused.
  void sort_bearings(const FrameInput& frame,
                     const std::vector<char>& crossing,
                     FrameEstimate* rec,
                     std::vector<const BearingObservation*>* fresh,
                     std::vector<BearingMeasurement>* z,
                     std::vector<int>* z_ids);
  // Inverse-depth blocks whose depth is now well known change parametrisation.
  void convert_known_depths();
  // Removes from obs (frame `frame`) the bearings guard_ahead marked before a track that
  // starts after frame `started_after`, records them as guarded; returns how many.
  int leave_out_ahead(std::vector<BearingObservation>* obs, int frame, int started_after);
  // Bearings left out ahead in a frame.
  int guarded_ahead(int frame) const;
  void end_bootstrap(FrameEstimate rec);
  void record_tracks();
  // The slot of a track (a joined track's feature while that is in the state), -1 when not
  // in the state.
  int slot_of(int track_id) const;
  // Joins the new tracks in `fresh` that continue a feature of the state
  // (CalibrationOptions::association.join_pieces) and appends their bearings to z / z_ids; returns
  // the new tracks left.
  std::vector<const BearingObservation*> join_pieces(std::vector<const BearingObservation*> fresh,
                                                     std::vector<BearingMeasurement>* z,
                                                     std::vector<int>* z_ids);
  CalibrationOptions options_;
  FilterState state_;
  Propagator propagator_;
  Updater updater_;
  FeatureInitializer initializer_;
  int frame_ = 0;
  std::vector<FrameEstimate> history_;
  std::map<int, TrackEstimate> tracks_;
  std::vector<TrackSplit> splits_;
  std::vector<BearingKey> guarded_;
  std::vector<BearingKey> rejected_;
  std::vector<TrackJoin> joins_;
  std::map<int, int> joined_to_;  // new track id -> the feature's track id
  int window_frames_ = 0;
  std::string window_failure_;
  bool bootstrapping_ = false;
  CalibrationRun window_;
  double window_heading_ = 0.0;
  double window_max_turn_ = 0.0;
  std::map<BearingKey, int> ahead_;  // guard_ahead
  std::map<int, int> ahead_count_;   // frame -> bearings left out ahead
};

}  // namespace omnivert::calib
