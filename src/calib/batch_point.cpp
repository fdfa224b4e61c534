#include "calib/batch_point.hpp"

#include "omnivert/calib/model.hpp"

namespace omnivert::calib {

std::vector<Eigen::Vector3d> dead_reckoning(const CalibrationRun& run, double wheel_base) {
  std::vector<Eigen::Vector3d> poses;
  poses.reserve(run.frames.size());
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    if (k > 0) {
      const FrameInput& f = run.frames[k];
      p = integrate_pose_lateral(p, f.d_right, f.d_left, f.lateral, wheel_base);
    }
    poses.push_back(p);
  }
  return poses;
}

BatchPoint batch_point_from_filter(const CalibrationRun& run,
                                   const CalibrationOptions& options,
                                   const FilterResult& filter) {
  BatchPoint b;
  b.poses = dead_reckoning(run, options.robot.wheel_base);
  b.extrinsics = filter.extrinsics;
  for (const auto& [id, t] : filter.tracks) {
    if (t.frame < 0 || t.frame >= static_cast<int>(b.poses.size())) continue;
    b.features[id] = feature_to_world(b.poses[t.frame], t.D_theta(0), t.D_theta(1));
  }
  return b;
}

}  // namespace omnivert::calib
