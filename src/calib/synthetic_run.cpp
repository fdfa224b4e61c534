#include "calib/synthetic_run.hpp"

#include <cmath>
#include <random>

#include "omnivert/calib/model.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::calib {

namespace {

struct Step {
  double d_right, d_left;
};

void add_straight(double length, double step, std::vector<Step>* steps) {
  const int n = std::max(1, static_cast<int>(std::lround(length / step)));
  for (int i = 0; i < n; ++i) steps->push_back({length / n, length / n});
}

void add_turn(double angle, double turn_step, double e, std::vector<Step>* steps) {
  const int n = std::max(1, static_cast<int>(std::lround(std::abs(angle) / turn_step)));
  const double dt = angle / n;  // eq. (15): d_theta = (d_R - d_L) / e
  for (int i = 0; i < n; ++i) steps->push_back({0.5 * e * dt, -0.5 * e * dt});
}

}  // namespace

SyntheticRun make_synthetic_run(const SyntheticRunOptions& o) {
  if (!(o.straight_length > 0.0) || !(o.step > 0.0) || !(o.turn_step > 0.0) ||
      !(o.wheel_base > 0.0) || o.num_features < 1 || !(o.min_distance > o.truth.rho) ||
      !(o.max_distance > o.min_distance) || !(o.bearing_sigma >= 0.0) ||
      !(o.track_bias_sigma >= 0.0) || !(o.odometry_K >= 0.0) || o.zigzag_legs < 1 ||
      !(o.visible_range >= 0.0) || !(o.bearing_correlation >= 0.0 && o.bearing_correlation < 1.0))
    throw InputError("synthetic run: invalid options");
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);

  std::vector<Step> steps;
  switch (o.trajectory) {
    case Trajectory::kPaper:
      add_straight(o.straight_length, o.step, &steps);
      add_turn(o.turn_angle, o.turn_step, o.wheel_base, &steps);
      break;
    case Trajectory::kZigzag:
      for (int leg = 0; leg < o.zigzag_legs; ++leg) {
        add_straight(o.straight_length / o.zigzag_legs, o.step, &steps);
        add_turn(leg % 2 == 0 ? o.zigzag_turn : -o.zigzag_turn, o.turn_step, o.wheel_base, &steps);
      }
      break;
    case Trajectory::kStraight:
      add_straight(o.straight_length, o.step, &steps);
      break;
  }

  SyntheticRun out;
  out.truth = o.truth;
  out.true_poses.push_back(Eigen::Vector3d::Zero());
  for (const Step& s : steps)
    out.true_poses.push_back(integrate_pose(out.true_poses.back(),
                                            s.d_right,
                                            s.d_left,
                                            o.wheel_base));  // Eq. (14)

  // Features: a random point of the path, a random direction, a distance in
  // [min_distance, max_distance]; kept if no robot position comes closer than min_distance.
  for (int attempts = 0; static_cast<int>(out.features.size()) < o.num_features; ++attempts) {
    if (attempts > 100000) throw InputError("synthetic run: cannot place the features");
    const auto k =
        static_cast<std::size_t>(uniform(rng) * out.true_poses.size()) % out.true_poses.size();
    const double a = kTwoPi * uniform(rng);
    const double d = o.min_distance + (o.max_distance - o.min_distance) * uniform(rng);
    const Eigen::Vector2d f =
        out.true_poses[k].head<2>() + d * Eigen::Vector2d(std::cos(a), std::sin(a));
    bool ok = true;
    for (const auto& p : out.true_poses) ok = ok && (p.head<2>() - f).norm() >= o.min_distance;
    if (ok) out.features.push_back(f);
  }

  // Frames: odometry with Chong-Kleeman noise (eq. 31), bearings with Gaussian noise.
  std::vector<int> track_of(out.features.size());
  std::vector<double> error(out.features.size(), 0.0);  // AR(1) bearing error per feature
  const double a = o.bearing_correlation, innovation = std::sqrt(1.0 - a * a);
  int next_id = 0;
  for (std::size_t j = 0; j < out.features.size(); ++j) {
    track_of[j] = next_id++;
    out.track_feature[track_of[j]] = static_cast<int>(j);
  }
  std::vector<double> bias(out.features.size(), 0.0);  // per line, all its pieces
  if (o.track_bias_sigma > 0.0) {
    std::mt19937_64 bias_rng(o.seed ^ 0x9e3779b97f4a7c15ULL);
    for (double& b : bias) b = o.track_bias_sigma * normal(bias_rng);
  }
  std::vector<bool> was_visible(out.features.size(), true);
  for (std::size_t k = 0; k < out.true_poses.size(); ++k) {
    FrameInput f;
    if (k > 0) {
      const Step& s = steps[k - 1];
      f.d_right = s.d_right + std::sqrt(o.odometry_K * std::abs(s.d_right)) * normal(rng);
      f.d_left = s.d_left + std::sqrt(o.odometry_K * std::abs(s.d_left)) * normal(rng);
    }
    const Eigen::Vector3d& pose = out.true_poses[k];
    const Eigen::Vector2d camera =
        pose.head<2>() + o.truth.rho * Eigen::Vector2d(std::cos(pose(2) + o.truth.phi),
                                                       std::sin(pose(2) + o.truth.phi));
    for (std::size_t j = 0; j < out.features.size(); ++j) {
      if (k > 0 && o.break_probability > 0.0 && uniform(rng) < o.break_probability) {
        track_of[j] = next_id++;
        out.track_feature[track_of[j]] = static_cast<int>(j);
      }
      const double n = normal(rng);
      if (o.visible_range > 0.0) {
        const bool visible = (out.features[j] - camera).norm() <= o.visible_range;
        if (visible && !was_visible[j]) {  // back in view: a new track
          track_of[j] = next_id++;
          out.track_feature[track_of[j]] = static_cast<int>(j);
        }
        was_visible[j] = visible;
        if (!visible) continue;
      }
      error[j] = k == 0 ? o.bearing_sigma * n : a * error[j] + innovation * o.bearing_sigma * n;
      const double beta =
          bearing_from_geometry(out.true_poses[k], out.features[j], o.truth) + error[j] + bias[j];
      f.observations.push_back({track_of[j], wrap_angle(beta)});
    }
    out.run.frames.push_back(std::move(f));
  }
  return out;
}

}  // namespace omnivert::calib
