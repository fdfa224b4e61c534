// The tracker's geometry without extrinsics (track_geometry.hpp): the axle's position from the
// wheels, rays meeting at a line, the camera's yaw from the sign of the parallax, and the
// triangulated prediction and links by prediction of the tracker.
#include "omnivert/match/track_geometry.hpp"

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/match/tracker.hpp"
#include "tracker_sequence.hpp"

namespace omnivert {
namespace {

using namespace tracker_testing;

TEST(TrackGeometry, AxlePositionFollowsEq14) {
  const double e = 0.5;
  OdometryAccumulator o;
  for (int k = 0; k < 10; ++k) o.add({0.1, 0.1}, e);  // 1 m straight along x
  const double quarter = 0.25 * kPi * e;              // wheel travel of a quarter turn
  for (int k = 0; k < 10; ++k) o.add({0.1 * quarter, -0.1 * quarter}, e);
  for (int k = 0; k < 10; ++k) o.add({0.1, 0.1}, e);  // 1 m along y
  EXPECT_NEAR(o.x, 1.0, 1e-12);
  EXPECT_NEAR(o.y, 1.0, 1e-12);
  EXPECT_NEAR(o.theta, 0.5 * kPi, 1e-12);
  EXPECT_NEAR(o.path_length, 2.0, 1e-12);
  // An arc of radius 1 m through a quarter turn in 100 steps: the midpoint rule of eq. (14).
  OdometryAccumulator arc;
  const double len = 0.5 * kPi / 100;
  for (int k = 0; k < 100; ++k) arc.add({len * (1 + 0.5 * e), len * (1 - 0.5 * e)}, e);
  EXPECT_NEAR(arc.x, 1.0, 1e-4);
  EXPECT_NEAR(arc.y, 1.0, 1e-4);
}

TEST(TrackGeometry, RaysMeetAtTheLine) {
  double x = 0, y = 0;
  ASSERT_TRUE(intersect_rays(0, 0, std::atan2(1, 2), 1, 0, std::atan2(1, 1), 0.01, &x, &y));
  EXPECT_NEAR(x, 2.0, 1e-12);
  EXPECT_NEAR(y, 1.0, 1e-12);
  // Parallel within the minimum angle, and a meeting point behind the second origin.
  EXPECT_FALSE(intersect_rays(0, 0, 0.3, 1, 0, 0.3 + 0.005, 0.01, &x, &y));
  EXPECT_FALSE(intersect_rays(0, 0, std::atan2(1, 2), 3, 0, std::atan2(-1, -1), 0.01, &x, &y));
}

// Lines around a robot driving straight along a random heading, seen by a camera with yaw Y:
// the votes on the sign of each line's parallax recover Y.
TEST(TrackGeometry, CameraYawFromTheSignOfTheParallax) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (double yaw : {0.0, -0.01, 1.56, 3.1, -2.0}) {
    CameraYawVotes votes;
    EXPECT_TRUE(std::isnan(votes.estimate()));
    for (int pair = 0; pair < 600; ++pair) {
      const double heading = kPi * uni(rng);
      const double px = 4.0 * uni(rng), py = 4.0 * uni(rng);
      if (std::hypot(px, py) < 0.5) continue;
      const double step = 0.1;
      auto bearing = [&](double s) {  // eq. (16), camera at the axle
        return wrap_angle(std::atan2(py - s * std::sin(heading), px - s * std::cos(heading)) -
                          heading - yaw);
      };
      std::normal_distribution<double> noise(0.0, 0.0005);
      const double b0 = bearing(0) + noise(rng), b1 = bearing(step) + noise(rng);
      votes.add(b0 + 0.5 * angle_diff(b1, b0), angle_diff(b1, b0));
    }
    SCOPED_TRACE(testing::Message() << "yaw " << yaw);
    const double estimate = votes.estimate();
    ASSERT_FALSE(std::isnan(estimate));
    EXPECT_LT(std::abs(angle_diff(estimate, yaw)), 0.05);
  }
}

// Where the lines of the two tracker tests stand: a near one first, the others far.
const std::vector<std::pair<double, double>> kPoints = {
    {0.6, 0.35}, {6.0, 3.0}, {-5.0, 4.0}, {-4.0, -6.0}, {7.0, -2.0}, {0.5, -8.0}};

// Frame f of a robot driving 0.1 m a frame along x from the origin, its camera at the axle with
// yaw `yaw`: one line of each of kPoints, of `polarity`, with the descriptor `descriptor(k)`.
FrameFeatures driven_past(int f,
                          double yaw,
                          int polarity,
                          const std::function<Eigen::RowVectorXf(std::size_t)>& descriptor) {
  FrameFeatures fr;
  fr.descriptors.resize(static_cast<Eigen::Index>(kPoints.size()), kPaperDescriptorSize);
  for (std::size_t k = 0; k < kPoints.size(); ++k) {
    VerticalLine v;
    v.bearing = wrap_angle(std::atan2(kPoints[k].second, kPoints[k].first - 0.1 * f) - yaw);
    v.polarity = polarity;
    fr.lines.push_back(v);
    fr.descriptors.row(static_cast<Eigen::Index>(k)) = descriptor(k);
  }
  return fr;
}

// The frames of the first test's scene at yaw 0.3 rad: every descriptor perturbed a little in
// each frame, the near line's changed by 0.9 in frame 3.
struct NearLineChangesInFrame3 {
  static constexpr double kYaw = 0.3;
  explicit NearLineChangesInFrame3(unsigned seed) : rng(seed) {
    for (std::size_t k = 0; k < kPoints.size(); ++k) d.push_back(random_descriptor(rng));
    changed = at_distance(d[0], random_descriptor(rng), 0.9);
  }
  FrameFeatures frame(int f) {
    return driven_past(f, kYaw, 1, [&](std::size_t k) -> Eigen::RowVectorXf {
      return k == 0 && f == 3 ? changed : perturb(d[k], 0.004f, rng);
    });
  }
  std::mt19937 rng;
  std::vector<Eigen::RowVectorXf> d;
  Eigen::RowVectorXf changed;
};

// A near line (0.6 m ahead, 0.35 m to the left) passed at 10 cm a frame: its bearing turns by
// 4.7, 6.2, then 8.2 degrees. In the last frame its descriptor has changed by 0.9 (beyond F1 and
// the confirmed F1's tests). The rates of its last link predict it 2 degrees short, beyond track
// continuity: a new track. The triangulated position predicts it exactly: with links by
// prediction it keeps its track. The other lines, far, keep theirs in every case.
TEST(Tracker, LinkByPredictionFollowsANearLineWhoseDescriptorChanged) {
  struct Case {
    bool triangulate;
    double predict_f1;
    bool linked;
  };
  for (const Case c : {Case{false, 0.0, false}, Case{true, 1.05, true}, Case{true, 0.5, false}}) {
    NearLineChangesInFrame3 scene(17);
    const auto& points = kPoints;
    const double yaw = NearLineChangesInFrame3::kYaw;
    auto frame = [&](int f) { return scene.frame(f); };
    TrackerOptions o = recommended_tracker_options(0.4);
    o.triangulate = c.triangulate;
    o.predict_f1 = c.predict_f1;
    o.camera_yaw = yaw;
    Tracker tracker(o);
    std::vector<TrackAssignment> out0, out;
    tracker.add_frame(frame(0), WheelIncrement{}, &out0);
    const WheelIncrement straight{0.1, 0.1};
    for (int f = 1; f <= 3; ++f) {
      tracker.add_frame(frame(f), straight, &out);
      SCOPED_TRACE(testing::Message() << "frame " << f << ", triangulate " << c.triangulate
                                      << ", predict F1 " << c.predict_f1);
      for (std::size_t k = 1; k < points.size(); ++k) EXPECT_EQ(out[k].track_id, out0[k].track_id);
      if (f < 3) {
        EXPECT_EQ(out[0].track_id, out0[0].track_id);
      } else if (c.linked) {
        EXPECT_EQ(out[0].track_id, out0[0].track_id);
        EXPECT_EQ(out[0].frames_back, 1);
        EXPECT_NEAR(out[0].distance, 0.9f, 0.01f);
        EXPECT_EQ(tracker.stats().linked_by_prediction, 1);
      } else {
        EXPECT_TRUE(out[0].is_new());
        EXPECT_EQ(tracker.stats().linked_by_prediction, 0);
      }
    }
  }
}

// The same near line with a descriptor that changes by 0.9 in every frame: it begins a new track
// in frames 0 and 1. In frame 2 the rays of frames 0 and 1 meet at the line and predict it: it
// continues frame 1's track, and in frame 3 that track's triangulated position links it again.
// Without links by prediction each frame begins a new track.
TEST(Tracker, ThreeRaysThatMeetLinkANearLineAgain) {
  for (const double predict_f1 : {0.0, 1.05}) {
    std::mt19937 rng(23);
    const auto& points = kPoints;
    std::vector<Eigen::RowVectorXf> d;
    for (std::size_t k = 0; k < points.size(); ++k) d.push_back(random_descriptor(rng));
    std::vector<Eigen::RowVectorXf> near = {d[0]};
    for (int f = 1; f <= 3; ++f)
      near.push_back(at_distance(near.back(), random_descriptor(rng), 0.9));
    const double yaw = -1.2;
    auto frame = [&](int f) {
      return driven_past(f, yaw, -1, [&](std::size_t k) -> Eigen::RowVectorXf {
        return k == 0 ? near[static_cast<std::size_t>(f)] : perturb(d[k], 0.004f, rng);
      });
    };
    TrackerOptions o = recommended_tracker_options(0.4);
    o.triangulate = true;
    o.predict_f1 = predict_f1;
    o.camera_yaw = yaw;
    Tracker tracker(o);
    std::vector<std::vector<TrackAssignment>> out(4);
    tracker.add_frame(frame(0), WheelIncrement{}, &out[0]);
    for (int f = 1; f <= 3; ++f) tracker.add_frame(frame(f), WheelIncrement{0.1, 0.1}, &out[f]);
    SCOPED_TRACE(testing::Message() << "predict F1 " << predict_f1);
    for (int f = 1; f <= 3; ++f)
      for (std::size_t k = 1; k < points.size(); ++k)
        EXPECT_EQ(out[f][k].track_id, out[0][k].track_id);
    EXPECT_TRUE(out[1][0].is_new());
    if (predict_f1 > 0) {
      EXPECT_EQ(out[2][0].track_id, out[1][0].track_id);
      EXPECT_EQ(out[3][0].track_id, out[1][0].track_id);
      EXPECT_EQ(tracker.stats().linked_by_prediction, 2);
    } else {
      EXPECT_TRUE(out[2][0].is_new());
      EXPECT_TRUE(out[3][0].is_new());
    }
  }
}

// A new value of the camera's yaw (a later estimate, here 1.15 degrees from the last) must not
// turn the predictions of the lines already located: they were triangulated with the old yaw
// and are predicted with it. Otherwise every prediction moves by the change, beyond track
// continuity's 0.8 degree, and every track breaks at once. The near line's descriptor changes by
// 0.9 in that frame, so that only its prediction can keep its track.
TEST(Tracker, ANewCameraYawDoesNotTurnTheLinesAlreadyLocated) {
  NearLineChangesInFrame3 scene(29);
  const double yaw = NearLineChangesInFrame3::kYaw;
  auto frame = [&](int f) { return scene.frame(f); };
  TrackerOptions o = recommended_tracker_options(0.4);
  o.triangulate = true;
  o.predict_f1 = 1.05;
  o.camera_yaw = yaw;
  Tracker tracker(o);
  std::vector<TrackAssignment> out0, out;
  tracker.add_frame(frame(0), WheelIncrement{}, &out0);
  for (int f = 1; f <= 3; ++f) {
    if (f == 3) tracker.set_camera_yaw(yaw + 0.02);
    tracker.add_frame(frame(f), WheelIncrement{0.1, 0.1}, &out);
    SCOPED_TRACE(testing::Message() << "frame " << f);
    for (std::size_t k = 0; k < kPoints.size(); ++k) {
      EXPECT_EQ(out[k].track_id, out0[k].track_id) << "line " << k;
      EXPECT_EQ(out[k].frames_back, 1) << "line " << k;
    }
  }
  EXPECT_EQ(tracker.stats().linked_by_prediction, 1);
}

}  // namespace
}  // namespace omnivert
