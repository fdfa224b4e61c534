#include "omnivert/calib/calibration_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "calib/filter_impl.hpp"
#include "calib/window.hpp"
#include "omnivert/calib/model.hpp"
#include "omnivert/calib/track_ids.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

namespace {
CalibrationOptions checked(const CalibrationOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("calibration options: " + why);
  return options;
}
}  // namespace

CalibrationFilter::CalibrationFilter(const CalibrationOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}
CalibrationFilter::~CalibrationFilter() = default;
CalibrationFilter::CalibrationFilter(const CalibrationFilter& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
CalibrationFilter& CalibrationFilter::operator=(const CalibrationFilter& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
CalibrationFilter::CalibrationFilter(CalibrationFilter&& other) noexcept = default;
CalibrationFilter& CalibrationFilter::operator=(CalibrationFilter&& other) noexcept = default;

void CalibrationFilter::process(const FrameInput& frame) { impl_->process(frame); }
void CalibrationFilter::guard_ahead(std::map<BearingKey, int> keys) {
  impl_->ahead_ = std::move(keys);
}
void CalibrationFilter::finish() { impl_->finish(); }
Extrinsics CalibrationFilter::extrinsics() const { return impl_->state_.extrinsics(); }
Eigen::Matrix3d CalibrationFilter::covariance() const {
  return impl_->state_.extrinsics_covariance();
}
int CalibrationFilter::num_features() const { return impl_->state_.num_features(); }
const std::vector<FrameEstimate>& CalibrationFilter::history() const { return impl_->history_; }
const std::map<int, TrackEstimate>& CalibrationFilter::tracks() const { return impl_->tracks_; }
const std::vector<TrackSplit>& CalibrationFilter::splits() const { return impl_->splits_; }
int CalibrationFilter::window_frames() const { return impl_->window_frames_; }
const std::string& CalibrationFilter::window_failure() const { return impl_->window_failure_; }
const std::vector<BearingKey>& CalibrationFilter::guarded() const { return impl_->guarded_; }
const std::vector<BearingKey>& CalibrationFilter::rejected() const { return impl_->rejected_; }
const std::vector<TrackJoin>& CalibrationFilter::joins() const { return impl_->joins_; }
int CalibrationFilter::frames_processed() const { return impl_->frame_; }
bool CalibrationFilter::bootstrapping() const { return impl_->bootstrapping_; }
const CalibrationOptions& CalibrationFilter::options() const { return impl_->options_; }

CalibrationFilter::Impl::Impl(const CalibrationOptions& options)
    : options_(checked(options)),
      state_(options.prior.mean,
             options.prior.sigma,
             options.filter.feature_init == FeatureInit::kAnchoredInverseDepth
                 ? ExtrinsicsParam::kCameraPose
                 : ExtrinsicsParam::kPaper),
      propagator_(options),
      updater_(options),
      initializer_(options),
      bootstrapping_(options.filter.feature_init == FeatureInit::kAnchoredInverseDepth &&
                     options.filter.bootstrap_rotation > 0.0) {}

void CalibrationFilter::Impl::process(const FrameInput& frame) {
  const std::string where = "frame " + std::to_string(frame_);
  if (!std::isfinite(frame.d_right) || !std::isfinite(frame.d_left) ||
      !std::isfinite(frame.lateral))
    throw InputError(where + ": wheel travel is not a finite number");
  std::set<int> seen;
  for (const BearingObservation& o : frame.observations) {
    if (!std::isfinite(o.beta))
      throw InputError(where + ": bearing of track " + std::to_string(o.track_id) +
                       " is not a finite number");
    if (!(std::isfinite(o.sigma_scale) && o.sigma_scale > 0.0))
      throw InputError(where + ": bearing of track " + std::to_string(o.track_id) +
                       " has a sigma scale that is not a positive number");
    if (!seen.insert(o.track_id).second)
      throw InputError(where + ": track " + std::to_string(o.track_id) +
                       " appears twice in one frame");
  }

  // The bearings left out ahead (guard_before_starts), as guarded ones, after the window.
  // In the window, only those before a track that starts after it (end_bootstrap): the
  // window's batch problem guards the frames before the starts it sees itself
  // (reject_crossings); left out there as well, they can hide the slip of a track onto a
  // neighbouring line from the window's split test, and the window ends off and overconfident.
  if (!ahead_.empty() && !bootstrapping_) {
    FrameInput kept = frame;
    if (leave_out_ahead(&kept.observations, frame_, -1) > 0) return admit(kept);
  }
  admit(frame);
}

int CalibrationFilter::Impl::leave_out_ahead(std::vector<BearingObservation>* obs,
                                             int frame,
                                             int started_after) {
  const auto gone = std::remove_if(obs->begin(), obs->end(), [&](const BearingObservation& o) {
    const auto it = ahead_.find({o.track_id, frame});
    return it != ahead_.end() && it->second > started_after;
  });
  const int n = static_cast<int>(obs->end() - gone);
  for (auto it = gone; it != obs->end(); ++it) guarded_.emplace_back(it->track_id, frame);
  obs->erase(gone, obs->end());
  if (n > 0) ahead_count_[frame] += n;
  return n;
}

int CalibrationFilter::Impl::guarded_ahead(int frame) const {
  const auto it = ahead_count_.find(frame);
  return it == ahead_count_.end() ? 0 : it->second;
}

void CalibrationFilter::Impl::admit(const FrameInput& frame) {
  // Delayed initialisation: the first bootstrap_frames frames are solved as a batch
  // (bootstrap_filter_state), the filter starts from that.
  if (bootstrapping_) {
    window_.frames.push_back(frame);
    FrameEstimate rec;
    rec.frame = frame_;
    rec.num_guarded = guarded_ahead(frame_);
    rec.extrinsics = state_.extrinsics();
    rec.covariance = state_.extrinsics_covariance();
    const int n = static_cast<int>(window_.frames.size());
    window_heading_ += (frame.d_right - frame.d_left) / options_.robot.wheel_base;  // eq. (15)
    if (n > 1) window_max_turn_ = std::max(window_max_turn_, std::abs(window_heading_));
    if ((n < options_.filter.bootstrap_min_frames ||
         window_max_turn_ < options_.filter.bootstrap_rotation) &&
        n < options_.filter.bootstrap_max_frames) {
      history_.push_back(rec);
      ++frame_;
      return;
    }
    end_bootstrap(rec);
    return;
  }
  step(frame);
}

void CalibrationFilter::Impl::finish() {
  if (!bootstrapping_ || window_.frames.empty()) return;
  --frame_;
  FrameEstimate rec = history_.back();
  history_.pop_back();
  end_bootstrap(rec);
}

void CalibrationFilter::Impl::end_bootstrap(FrameEstimate rec) {
  {
    bootstrapping_ = false;
    window_frames_ = static_cast<int>(window_.frames.size());
    // Bearings before a line whose track starts after the window (guard_before_starts): the
    // window cannot see that line, whose detections push the bearings beside it before its
    // track starts (CrossingGuard.BeforeATrackStartsBesideAnother).
    if (!ahead_.empty()) {
      const int first = frame_ - static_cast<int>(window_.frames.size()) + 1;
      for (int k = 0; k < static_cast<int>(window_.frames.size()); ++k) {
        const int n = leave_out_ahead(
            &window_.frames[static_cast<std::size_t>(k)].observations, first + k, frame_);
        const std::size_t h = static_cast<std::size_t>(first + k);  // history_ ends before rec
        (h < history_.size() ? history_[h].num_guarded : rec.num_guarded) += n;
      }
    }
    std::string why;
    BootstrapDetails details;
    if (bootstrap_filter_state(window_, options_, &state_, &why, &details)) {
      const int first = frame_ - static_cast<int>(window_.frames.size()) + 1;
      for (auto& [id, t] : details.tracks) {
        t.frame += first;
        tracks_[id] = t;
      }
      for (const auto& [id, frame] : details.splits) splits_.emplace_back(id, frame + first);
      // Pieces of one line joined in the window: later bearings of any piece are the line's.
      for (const auto& [id, root] : join_roots(details.joins)) {
        joined_to_[id] = root;
        joins_.emplace_back(root, id);
        if (const auto t = tracks_.find(root); t != tracks_.end()) {
          tracks_[id] = t->second;
          tracks_[id].track_id = id;
        }
      }
      for (const auto& [id, frame] : details.guarded) {
        guarded_.emplace_back(id, frame + first);
        const std::size_t k = static_cast<std::size_t>(frame + first);  // history_ ends before rec
        ++(k < history_.size() ? history_[k].num_guarded : rec.num_guarded);
      }
      for (const auto& [id, frame] : details.rejected) {
        rejected_.emplace_back(id, frame + first);
        const std::size_t k = static_cast<std::size_t>(frame + first);
        ++(k < history_.size() ? history_[k].num_rejected : rec.num_rejected);
      }
      rec.extrinsics = state_.extrinsics();
      rec.covariance = state_.extrinsics_covariance();
      rec.num_features = state_.num_features();
      rec.num_new = state_.num_features();
      history_.push_back(rec);
      record_tracks();
      ++frame_;
      window_.frames.clear();
      return;
    }
    // The window could not be solved: run the plain filter over it (and say so: the plain
    // filter from the rough prior can end millimetres off, result_warnings).
    window_failure_ = why.empty() ? "unknown reason" : why;
    const int first = frame_ - static_cast<int>(window_.frames.size()) + 1;
    history_.resize(first);
    frame_ = first;
    CalibrationRun w = std::move(window_);
    window_.frames.clear();
    for (const FrameInput& f : w.frames) step(f);
  }
}

void CalibrationFilter::Impl::step(const FrameInput& frame) {
  FrameEstimate rec;
  rec.frame = frame_;
  rec.num_guarded = guarded_ahead(frame_);
  // Prediction, eq. (29). (The first frame carries no travel; propagating zero is harmless.)
  if (state_.num_features() > 0) propagator_.propagate(frame, &state_);

  // Updates of the tracks already in the state, eq. (30), all bearings of the frame at once.
  const std::vector<char> crossing = crossing_entries(frame);
  std::vector<const BearingObservation*> fresh;
  std::vector<BearingMeasurement> z;
  std::vector<int> z_ids;  // each bearing's own track id (a joined track's, not its feature's)
  sort_bearings(frame, crossing, &rec, &fresh, &z, &z_ids);
  if (options_.association.join_pieces && !fresh.empty())
    fresh = join_pieces(std::move(fresh), &z, &z_ids);
  const std::vector<BearingUpdateResult> results = updater_.update(z, &state_);
  for (std::size_t k = 0; k < z.size(); ++k) {
    if (results[k].accepted) {
      ++rec.num_updates;
      ++state_.mutable_slots()[z[k].slot].num_updates;
    } else {
      ++rec.num_rejected;
      rejected_.emplace_back(z_ids[k], frame_);
    }
  }
  // Tracks that start enter the state (their first bearing is used by the initialisation).
  for (const BearingObservation* o : fresh) {
    initializer_.initialize(o->track_id, o->beta, frame_, &state_, o->sigma_scale);
    ++rec.num_new;
  }
  convert_known_depths();
  record_tracks();
  // Tracks that ended leave the state (marginalisation).
  for (int s = state_.num_features() - 1; s >= 0; --s)
    if (frame_ - state_.slots()[s].last_seen_frame > options_.association.max_missed_frames)
      state_.remove_feature(s);

  rec.extrinsics = state_.extrinsics();
  rec.covariance = state_.extrinsics_covariance();
  rec.num_features = state_.num_features();
  history_.push_back(rec);
  ++frame_;
}

// The crossing guard (CalibrationOptions::association.crossing_guard): a feature whose direction is
// within the guard of another line's is not updated in this frame: the extractor sees the two lines
// as one there, and the bearings are pulled or pushed
// (docs/theory/association.md#lines-that-cross). The other line is a feature of the state (its
// track seen within the last max_missed_frames frames) or a track that starts in this frame. A
// feature's direction is its bearing in this frame where it has one, else its predicted bearing
// (eq. 27). A track that starts within the guard of another line enters the state at its first
// bearing outside it: entered inside, its first bearing is pulled towards the other line, and with
// its depth unknown its prediction stays by the other line, which is then left out as long.
std::vector<char> CalibrationFilter::Impl::crossing_entries(const FrameInput& frame) const {
  const int n = state_.num_features();
  std::vector<char> crossing(frame.observations.size() + static_cast<std::size_t>(n), 0);
  if (options_.association.crossing_guard > 0.0) {
    const Extrinsics ex = state_.extrinsics();
    // Entries: the state's features (ids 0 .. n - 1), then the frame's new tracks (n + their
    // index in the frame).
    std::vector<double> direction(static_cast<std::size_t>(n),
                                  std::numeric_limits<double>::quiet_NaN());
    std::vector<std::pair<double, int>> lines;
    for (std::size_t i = 0; i < frame.observations.size(); ++i) {
      const BearingObservation& o = frame.observations[i];
      const int s = slot_of(o.track_id);
      if (s < 0)
        lines.emplace_back(wrap_angle(o.beta), n + static_cast<int>(i));
      else if (std::isnan(direction[static_cast<std::size_t>(s)]))
        direction[static_cast<std::size_t>(s)] = wrap_angle(o.beta);
    }
    std::vector<char> unseen(static_cast<std::size_t>(n), 0);
    for (int s = 0; s < n; ++s) {
      double b = direction[static_cast<std::size_t>(s)];
      if (std::isnan(b)) {
        const Eigen::Vector2d d = state_.feature_distance_form(s);
        if (!(d.allFinite() && d(0) > 0.0)) continue;
        b = predict_bearing(d(0), d(1), ex);
        unseen[static_cast<std::size_t>(s)] = 1;
      }
      lines.emplace_back(b, s);
    }
    // A new track beside a feature unseen in this frame may be that feature's line found
    // again (join_pieces decides), not another line.
    const auto maybe_same = [&](int a, int b) {
      if (a > b) std::swap(a, b);
      return a < n && b >= n && unseen[static_cast<std::size_t>(a)];
    };
    for (int e :
         crowded_directions(std::move(lines), options_.association.crossing_guard, maybe_same))
      crossing[static_cast<std::size_t>(e)] = 1;
  }
  return crossing;
}

void CalibrationFilter::Impl::sort_bearings(const FrameInput& frame,
                                            const std::vector<char>& crossing,
                                            FrameEstimate* rec,
                                            std::vector<const BearingObservation*>* fresh,
                                            std::vector<BearingMeasurement>* z,
                                            std::vector<int>* z_ids) {
  const int n = state_.num_features();
  std::set<int> measured;  // slots with a bearing in this frame
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    const BearingObservation& o = frame.observations[i];
    const int slot = slot_of(o.track_id);
    if (slot >= 0) state_.mutable_slots()[slot].last_seen_frame = frame_;
    if (crossing[slot >= 0 ? static_cast<std::size_t>(slot) : static_cast<std::size_t>(n) + i]) {
      ++rec->num_guarded;
      guarded_.emplace_back(o.track_id, frame_);
      continue;
    }
    if (slot < 0) {
      fresh->push_back(&o);
      continue;
    }
    if (!measured.insert(slot).second) {
      // A feature's old track came back beside the track joined to it: one line seen twice
      // is not a bearing of eq. (30); the second is refused.
      ++rec->num_rejected;
      rejected_.emplace_back(o.track_id, frame_);
      continue;
    }
    z->push_back({slot, o.beta, o.sigma_scale});
    z_ids->push_back(o.track_id);
  }
}

// (D, theta) of eq. (28) for kInverseDistance, a robot-frame point for kAnchored.
void CalibrationFilter::Impl::convert_known_depths() {
  if (options_.filter.convert_ratio > 0.0) {
    for (int s = 0; s < state_.num_features(); ++s) {
      const FeatureSlot& slot = state_.slots()[s];
      if (slot.param == FeatureParam::kInverseDistance) {
        const int i = slot.index;
        const double q = state_.x()(i);
        if (std::sqrt(state_.P()(i, i)) < options_.filter.convert_ratio * q) {
          const Eigen::Vector2d y(1.0 / q, state_.x()(i + 1));
          const Eigen::Matrix2d J = (Eigen::Matrix2d() << -1.0 / (q * q), 0, 0, 1).finished();
          state_.reparametrise(s, FeatureParam::kDistance, y, J);
        }
      } else if (slot.param == FeatureParam::kAnchored) {
        const int i = slot.index;
        const double q = state_.x()(i + 3);
        if (std::sqrt(state_.P()(i + 3, i + 3)) < options_.filter.convert_ratio * q) {
          Eigen::Matrix<double, 2, 4> J;
          const Eigen::Vector2d y = anchored_to_point(state_.x().segment<4>(i), &J);
          state_.reparametrise(s, FeatureParam::kPoint, y, J);
        }
      }
    }
  }
}

int CalibrationFilter::Impl::slot_of(int track_id) const {
  // A joined track's feature, while it is in the state; after it left (its line unseen for
  // max_missed_frames frames) the track is a feature of its own again once it has entered.
  if (const auto it = joined_to_.find(track_id); it != joined_to_.end())
    if (const int s = state_.find(it->second); s >= 0) return s;
  return state_.find(track_id);
}

// CalibrationOptions::association.join_pieces. Candidates for a new track's first bearing: the
// features of the state whose point is known (kPoint, kDistance: a feature still in inverse depth
// predicts a wide fan of bearings, where any line would pass), not seen in this frame and with no
// feature seen in this frame predicted within the crossing guard of it, whose gate (eq. 30's
// innovation, Updater::innovation_chi2) the bearing passes, and whose predicted bearing is sharp
// (join_prediction_sigmas: on a long run through a line-rich room, new tracks of other lines
// start within the gate of a wide prediction). A new track with exactly one candidate, which no
// other new track has as a candidate, continues it. (Only the features seen in this frame crowd
// a candidate: the old piece of a line that was not joined stays in the state for
// max_missed_frames frames unseen, and would crowd the new piece of the same line. Without the
// crowding test a new track of a door's edge can be joined to the feature of the edge beside
// it, which puts the filter a degree off in yaw.)
std::vector<const BearingObservation*> CalibrationFilter::Impl::join_pieces(
    std::vector<const BearingObservation*> fresh,
    std::vector<BearingMeasurement>* z,
    std::vector<int>* z_ids) {
  // Predicted bearings (eq. 27) of the features seen in this frame: a candidate with one of
  // them within the crossing guard is where the extractor may take one line for the other.
  const Extrinsics ex = state_.extrinsics();
  std::vector<double> seen_now;
  for (int s = 0; s < state_.num_features(); ++s) {
    if (state_.slots()[s].last_seen_frame != frame_) continue;
    const Eigen::Vector2d d = state_.feature_distance_form(s);
    if (d.allFinite() && d(0) > 0.0) seen_now.push_back(predict_bearing(d(0), d(1), ex));
  }
  auto crowded = [&](int s) {
    const Eigen::Vector2d d = state_.feature_distance_form(s);
    if (!(d.allFinite() && d(0) > 0.0)) return true;
    const double b = predict_bearing(d(0), d(1), ex);
    for (double o : seen_now)
      if (std::abs(angle_diff(o, b)) < options_.association.crossing_guard) return true;
    return false;
  };
  // The features that may be continued, the same for every new track of the frame.
  std::vector<int> eligible;
  for (int s = 0; s < state_.num_features(); ++s) {
    const FeatureSlot& slot = state_.slots()[s];
    if (slot.last_seen_frame != frame_ &&
        (slot.param == FeatureParam::kPoint || slot.param == FeatureParam::kDistance) &&
        !crowded(s))
      eligible.push_back(s);
  }
  const double max_sigma =
      options_.association.join_prediction_sigmas * options_.noise.bearing_sigma;
  std::vector<int> candidate(fresh.size(), -1);
  std::map<int, int> claims;  // slot -> new tracks that have it as a candidate
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    int found = 0;
    for (int s : eligible) {
      const BearingMeasurement m{s, fresh[i]->beta, fresh[i]->sigma_scale};
      double predicted_var = 0.0;
      if (!(updater_.innovation_chi2(state_, m, &predicted_var) <= updater_.gate())) continue;
      if (max_sigma > 0.0 && predicted_var > std::pow(max_sigma * fresh[i]->sigma_scale, 2))
        continue;
      ++claims[s];
      candidate[i] = s;
      ++found;
    }
    if (found != 1) candidate[i] = -1;
  }
  std::vector<const BearingObservation*> left;
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    const int s = candidate[i];
    if (s < 0 || claims[s] != 1) {
      left.push_back(fresh[i]);
      continue;
    }
    FeatureSlot& slot = state_.mutable_slots()[s];
    joined_to_[fresh[i]->track_id] = slot.track_id;
    joins_.emplace_back(slot.track_id, fresh[i]->track_id);
    slot.last_seen_frame = frame_;
    z->push_back({s, fresh[i]->beta, fresh[i]->sigma_scale});
    z_ids->push_back(fresh[i]->track_id);
  }
  return left;
}

void CalibrationFilter::Impl::record_tracks() {
  std::map<int, std::vector<int>> joined;  // feature's track id -> tracks joined to it
  for (const auto& [id, to] : joined_to_) joined[to].push_back(id);
  for (int s = 0; s < state_.num_features(); ++s) {
    const FeatureSlot& slot = state_.slots()[s];
    if (slot.last_seen_frame != frame_ && tracks_.count(slot.track_id)) continue;
    TrackEstimate& t = tracks_[slot.track_id];
    t.track_id = slot.track_id;
    t.frame = frame_;
    t.D_theta = state_.feature_distance_form(s, &t.covariance);
    t.num_updates = slot.num_updates;
    if (const auto it = joined.find(slot.track_id); it != joined.end())
      for (int id : it->second) {
        tracks_[id] = t;
        tracks_[id].track_id = id;
      }
  }
}

std::map<BearingKey, int> guard_before_starts(const CalibrationRun& run,
                                              const CalibrationOptions& options) {
  std::map<BearingKey, int> out;
  const double guard = options.association.crossing_guard;
  if (!(guard > 0.0)) return out;
  std::map<int, std::map<int, double>> at;  // track id -> frame -> bearing
  for (int k = 0; k < static_cast<int>(run.frames.size()); ++k)
    for (const BearingObservation& o : run.frames[static_cast<std::size_t>(k)].observations)
      at[o.track_id][k] = o.beta;
  constexpr int kRateFrames = 3;
  for (const auto& [b, of_b] : at) {
    const int k0 = of_b.begin()->first;
    for (const auto& [a, of_a] : at) {
      const auto a0 = of_a.find(k0);
      if (a == b || a0 == of_a.end() || of_a.begin()->first >= k0) continue;
      // The separation b - a at k0, and its rate over b's first frames that both saw.
      const double sep0 = angle_diff(of_b.begin()->second, a0->second);
      double rate = 0.0;
      for (auto it = std::next(of_b.begin()); it != of_b.end() && it->first <= k0 + kRateFrames;
           ++it)
        if (const auto ai = of_a.find(it->first); ai != of_a.end())
          rate = (angle_diff(it->second, ai->second) - sep0) / (it->first - k0);
      for (auto it = of_a.lower_bound(k0 - options.association.max_missed_frames); it != a0; ++it)
        if (std::abs(sep0 - rate * (k0 - it->first)) < guard) {
          const auto [o, fresh] = out.emplace(BearingKey{a, it->first}, k0);
          if (!fresh) o->second = std::min(o->second, k0);
        }
    }
  }
  return out;
}

FilterResult run_filter(const CalibrationRun& run, const CalibrationOptions& options) {
  CalibrationFilter filter(options);
  filter.guard_ahead(guard_before_starts(run, options));
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    filter.process(run.frames[k]);
    if (options.progress) options.progress("filter", k + 1, run.frames.size());
  }
  filter.finish();
  return {filter.extrinsics(),
          filter.covariance(),
          filter.history(),
          filter.tracks(),
          filter.splits(),
          filter.window_frames(),
          filter.window_failure(),
          filter.guarded(),
          filter.rejected(),
          filter.joins()};
}

}  // namespace omnivert::calib
