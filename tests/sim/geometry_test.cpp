// Camera model, trajectories and worlds: known geometry in, known answer out.

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/sim/camera_model.hpp"
#include "omnivert/sim/trajectory.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {
namespace {

namespace fs = std::filesystem;

TEST(CameraModel, RadiusElevationRoundTripAndMonotonic) {
  CatadioptricCamera cam;
  double prev = -1;
  for (double el = -1.5; el < std::asin(cam.xi) - 0.05; el += 0.01) {
    const double r = cam.radius_of_elevation(el);
    EXPECT_GT(r, prev);
    prev = r;
    EXPECT_NEAR(cam.elevation_of_radius(r), el, 1e-12);
  }
  EXPECT_NEAR(cam.elevation_of_radius(0.0), -kPi / 2, 1e-12);
}

TEST(CameraModel, ProjectionFollowsTheBearingConvention) {
  // docs/theory/conventions.md: with bearing_sign +1 a point at bearing beta is drawn at
  // (cx + r cos beta, cy + r sin beta); with -1 at (cx + r cos beta, cy - r sin beta).
  for (int sign : {1, -1}) {
    CatadioptricCamera cam;
    cam.bearing_sign = sign;
    for (double beta : {0.0, 0.5, 2.0, -2.8}) {
      const double el = 0.1;
      const Eigen::Vector3d p(3 * std::cos(beta), 3 * std::sin(beta), 3 * std::tan(el));
      Eigen::Vector2d px;
      ASSERT_TRUE(cam.project(p, px));
      const double r = cam.radius_of_elevation(el);
      EXPECT_NEAR(px.x(), cam.cx + r * std::cos(beta), 1e-9);
      EXPECT_NEAR(px.y(), cam.cy + sign * r * std::sin(beta), 1e-9);
      EXPECT_NEAR(
          cam.geometry().bearing_of_image_angle(std::atan2(px.y() - cam.cy, px.x() - cam.cx)),
          beta,
          1e-12);
    }
  }
  CatadioptricCamera cam;
  Eigen::Vector2d px;
  EXPECT_FALSE(cam.project({0.1, 0, 10.0}, px));  // beyond asin(xi)
  EXPECT_TRUE(cam.validate().empty());
}

double path_length(const std::vector<MotionPiece>& m) {
  double s = 0;
  for (const auto& p : m) s += std::abs(p.v) * (p.t1 - p.t0);
  return s;
}

TEST(Trajectory, PaperPresetIsTheExperimentOfSection9) {
  const Trajectory t = load_trajectory("paper");
  const auto m = t.pieces(Pose2::Zero());
  const Pose2 end = pose_at(m, duration(m));
  EXPECT_NEAR(end.x(), 2.3, 1e-9);
  EXPECT_NEAR(end.y(), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(wrap_angle(end.z())), kPi, 1e-9);
  EXPECT_NEAR(t.speed / 3.0, 0.038, 1e-9);  // 3.8 cm between frames at 3 Hz
  // The straight part takes about 60 frames (Sec. 9.2: "after about 60 frames").
  EXPECT_NEAR(m.front().t1 * 3.0, 60.5, 0.1);
  // Then a turn in place: the wheel centre does not move.
  EXPECT_NEAR((pose_at(m, m.front().t1).head<2>() - end.head<2>()).norm(), 0.0, 1e-12);
}

TEST(Trajectory, TourIsLongEnough) {
  const Trajectory t = load_trajectory("tour");
  const auto m = t.pieces(Pose2::Zero());
  const double frames = duration(m) * 3.0;
  EXPECT_GE(frames, 1800);
  EXPECT_NEAR(t.speed / 3.0, 0.05, 1e-12);
  EXPECT_GT(path_length(m), 85.0);
  const Pose2 end = pose_at(m, duration(m));  // closed loops
  EXPECT_NEAR(end.head<2>().norm(), 0.0, 1e-6);
}

TEST(Trajectory, ArcAndPoseIntegrationAreExact) {
  Trajectory t;
  t.speed = 0.5;
  t.segments = {{Segment::Kind::kArc, kPi, kPi, 0}};  // half circle of radius 1
  const auto m = t.pieces(Pose2::Zero());
  const Pose2 end = pose_at(m, duration(m));
  EXPECT_NEAR(end.x(), 0.0, 1e-12);
  EXPECT_NEAR(end.y(), 2.0, 1e-12);
  const Pose2 mid = pose_at(m, duration(m) / 2);
  EXPECT_NEAR(mid.x(), 1.0, 1e-12);
  EXPECT_NEAR(mid.y(), 1.0, 1e-12);
}

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_geom_" + std::to_string(::getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
  fs::path dir;
};

using TrajectoryFile = TempDir;
using WorldFile = TempDir;

TEST_F(TrajectoryFile, ReadsSegmentsAndRepeat) {
  const std::string f =
      write("t.yaml",
            "speed: 0.2\nturn_rate: 0.5\nstart: [1, 2, 0]\nrepeat: 2\nsegments:\n"
            "  - straight: 1.0\n  - turn_deg: 90\n  - arc: {length: 0.5, angle_deg: 30}\n"
            "  - wait: 2\n");
  const Trajectory t = load_trajectory(f);
  ASSERT_EQ(t.segments.size(), 8u);
  EXPECT_TRUE(t.has_start);
  EXPECT_NEAR(t.segments[1].angle, kPi / 2, 1e-12);
  const auto m = t.pieces(t.start);
  EXPECT_NEAR(duration(m), 2 * (1.0 / 0.2 + (kPi / 2) / 0.5 + 0.5 / 0.2 + 2.0), 1e-9);
}

TEST_F(TrajectoryFile, BadSegmentNamesFileAndLine) {
  const std::string f = write("bad.yaml", "segments:\n  - straight: 1.0\n  - jump: 2\n");
  try {
    load_trajectory(f);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              f + ":3: unknown segment 'jump' (expected straight, turn_deg, arc or wait)");
  }
  EXPECT_THROW(load_trajectory("nonsense"), InputError);
}

TEST_F(WorldFile, PresetsRoundTripThroughYaml) {
  for (const std::string& name : world_presets()) {
    const World w = world_preset(name);
    EXPECT_TRUE(w.validate().empty()) << name;
    const auto edges = w.edges();
    EXPECT_GT(edges.size(), 40u) << name;
    const std::string f = (dir / (name + ".yaml")).string();
    save_world(w, f);
    const World back = load_world(f);
    ASSERT_EQ(back.walls.size(), w.walls.size());
    const auto edges2 = back.edges();
    ASSERT_EQ(edges2.size(), edges.size());
    for (std::size_t i = 0; i < edges.size(); ++i) {
      EXPECT_LT((edges[i].p - edges2[i].p).norm(), 1e-6);
      EXPECT_NEAR(edges[i].z1, edges2[i].z1, 1e-6);
    }
  }
}

TEST_F(WorldFile, UserWorldWithBoxesAndPartialHeightEdges) {
  const std::string f = write("w.yaml",
                              "height: 2.5\nwalls:\n"
                              "  - {from: [0, 0], to: [4, 0], intensity: 150,\n"
                              "     panels: [{at: [1, 2], z: [0, 2.0], intensity: 60}]}\n"
                              "boxes:\n  - {center: [2, 2], size: [0.4, 0.4], height: 1.0}\n");
  const World w = load_world(f);
  ASSERT_EQ(w.walls.size(), 5u);
  const auto edges = w.edges();
  ASSERT_EQ(edges.size(), 8u);  // 2 wall ends, 2 door sides, 4 box corners
  EXPECT_NEAR(edges[2].p.x(), 1.0, 1e-12);
  EXPECT_NEAR(edges[2].z1, 2.0, 1e-12);
  EXPECT_NEAR(edges[7].z1, 1.0, 1e-12);
}

TEST_F(WorldFile, BadValuesNameFileAndLine) {
  const std::string f =
      write("bad.yaml",
            "walls:\n  - from: [0, 0]\n    to: [1, 0]\n    panels:\n"
            "      - {at: [0.2, 0.5], z: [0, 1], intensity: 3, pattern: zebra}\n");
  try {
    load_world(f);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              f + ":5: unknown pattern 'zebra' (expected flat, stripes or wave)");
  }
  const std::string g = write("bad2.yaml", "walls:\n  - from: [0, 0]\n");
  try {
    load_world(g);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), g + ":2: missing required field 'to: [x, y]'");
  }
}

}  // namespace
}  // namespace omnivert::sim
