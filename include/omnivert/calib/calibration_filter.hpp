#pragma once
// The self-calibration EKF of paper Sec. 8.2 (Martinelli et al. 2006 extended to many
// features): feed it one FrameInput per image; it propagates with the wheel travels
// (eq. 29, 31), updates with the bearings of the tracks it knows (eq. 30), adds the tracks
// that start (FeatureInitializer) and marginalises the tracks that ended (not seen for
// options.association.max_missed_frames frames).
//
//   CalibrationFilter filter(options);
//   for (const FrameInput& f : frames) filter.process(f);
//   filter.finish();
//   Extrinsics ex = filter.extrinsics();  Eigen::Matrix3d C = filter.covariance();

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "omnivert/calib/options.hpp"
#include "omnivert/calib/types.hpp"

namespace omnivert::calib {

// Per-frame record (for states.csv and the convergence plot, Fig. 25).
struct FrameEstimate {
  int frame = 0;
  Extrinsics extrinsics;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int num_features = 0;  // in the state after this frame
  int num_updates = 0;   // bearings used
  int num_rejected = 0;  // bearings refused by the chi-square gate
  int num_new = 0;       // tracks that entered
  int num_guarded =
      0;  // bearings left out where lines cross (CalibrationOptions::association.crossing_guard)
};

// The last estimate of a track while it was in the state: (D, theta) relative to the robot
// at frame `frame`.
struct TrackEstimate {
  int track_id = -1;
  int frame = -1;
  Eigen::Vector2d D_theta = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  int num_updates = 0;
};

class CalibrationFilter {
 public:
  // Throws omnivert::InputError when !options.IsValid().
  explicit CalibrationFilter(const CalibrationOptions& options);
  ~CalibrationFilter();
  CalibrationFilter(const CalibrationFilter& other);
  CalibrationFilter& operator=(const CalibrationFilter& other);
  CalibrationFilter(CalibrationFilter&& other) noexcept;
  CalibrationFilter& operator=(CalibrationFilter&& other) noexcept;

  // One image frame. Throws InputError on non-finite wheel travel or bearings, or a track id
  // repeated within the frame.
  void process(const FrameInput& frame);
  // Bearings (track id, frame) -> the frame where the track of the line beside them starts,
  // to leave out as guarded (guard_before_starts; a filter fed frame by frame does not know
  // them, run_filter does).
  void guard_ahead(std::map<BearingKey, int> keys);
  // End of the run: solves a pending bootstrap window (a run that never turned). Call once
  // after the last frame before reading the estimate.
  void finish();

  Extrinsics extrinsics() const;
  Eigen::Matrix3d covariance() const;
  // Features in the state now (eq. 28's Z).
  int num_features() const;
  const std::vector<FrameEstimate>& history() const;
  const std::map<int, TrackEstimate>& tracks() const;
  // Tracks split in the bootstrap window (a track that slipped onto a neighbouring line):
  // (tracker's track id, first frame of the new part); see split_tracks (track_ids.hpp).
  const std::vector<TrackSplit>& splits() const;
  // The bootstrap window: how many frames it held (0: none), and, when it could not be
  // solved, why (the filter then ran over it from the prior, undelayed).
  int window_frames() const;
  const std::string& window_failure() const;
  // Bearings left out where lines cross (CalibrationOptions::association.crossing_guard), in the
  // window and after: (tracker's track id, frame).
  const std::vector<BearingKey>& guarded() const;
  // Bearings refused by the chi-square gate, in the window and after (tracker's track id,
  // frame). The bound of Sec. 8.1 for the filter's estimate is computed without these and
  // the guarded ones (calibrate()).
  const std::vector<BearingKey>& rejected() const;
  // New tracks taken for the continuation of a feature in the state
  // (CalibrationOptions::association.join_pieces): (the feature's track id, the new track's id).
  // The new track's bearings update that feature, and tracks() lists it with the feature's
  // estimate.
  const std::vector<TrackJoin>& joins() const;
  int frames_processed() const;
  // Whether the start-up window is still collecting frames (the estimate is then the prior's;
  // it is solved at the first turn of filter.bootstrap_rotation, or by finish()).
  bool bootstrapping() const;
  const CalibrationOptions& options() const;

 private:
  // The EKF's state, models and bookkeeping (src/calib/filter_impl.hpp).
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The crossing guard ahead of a track's start (CalibrationOptions::association.crossing_guard): a
// track often starts where its line parts from another, the extractor having seen the two as one
// before (the other line's bearings pulled or pushed meanwhile), and the filter, which knows a line
// once its track has started, cannot guard those frames as the batch problems do (reject_crossings
// widens each track's span by max_missed_frames). For each track b and each track a seen in
// b's first frame k0 (and before it), the separation b - a is carried back from k0 at its
// rate over b's first 3 frames both saw; a's bearings over the max_missed_frames frames
// before k0 where it is within the guard are returned: (track id, frame index in run) -> k0
// (the earliest, where several lines start beside it).
// (A line beside another before its track starts pushes that one's bearings off, and the
// filter ends off by several of its sigmas: CrossingGuard.BeforeATrackStartsBesideAnother.)
std::map<BearingKey, int> guard_before_starts(const CalibrationRun& run,
                                              const CalibrationOptions& options);

// Runs the filter over a whole run.
struct FilterResult {
  Extrinsics extrinsics;
  Eigen::Matrix3d covariance;
  std::vector<FrameEstimate> history;
  std::map<int, TrackEstimate> tracks;
  std::vector<TrackSplit> splits;    // CalibrationFilter::splits
  int window_frames = 0;             // CalibrationFilter::window_frames
  std::string window_failure;        // CalibrationFilter::window_failure
  std::vector<BearingKey> guarded;   // CalibrationFilter::guarded
  std::vector<BearingKey> rejected;  // CalibrationFilter::rejected
  std::vector<TrackJoin> joins;      // CalibrationFilter::joins
};
FilterResult run_filter(const CalibrationRun& run, const CalibrationOptions& options);

}  // namespace omnivert::calib
