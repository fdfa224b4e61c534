// People walking through the scene (sim/people.hpp): they walk back and forth along their
// path; painted where an upright cylinder of their width and height projects (eq. 16-17 for
// its azimuth, the camera model's radius of elevation for its feet and head), nowhere else.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/sim/people.hpp"

namespace omnivert::sim {
namespace {

TEST(People, WalkBackAndForth) {
  Person p;
  p.a = {0, 0};
  p.b = {2, 0};
  p.speed = 1.0;
  p.phase = 0.0;
  EXPECT_NEAR(person_position(p, 0.5).x(), 0.5, 1e-12);
  EXPECT_NEAR(person_position(p, 2.5).x(), 1.5, 1e-12);  // on the way back
  EXPECT_NEAR(person_position(p, 4.0).x(), 0.0, 1e-12);  // one return trip
  p.phase = 0.25;                                        // a quarter of the trip ahead
  EXPECT_NEAR(person_position(p, 0.0).x(), 1.0, 1e-12);
}

// A person 0.5 m wide and 1.7 m tall, 2 m from the camera at world azimuth 60 degrees; the
// camera at (1, -0.5), 0.9 m high, yaw 20 degrees.
struct Scene {
  CatadioptricCamera cam;
  CameraPose pose;
  Person person;
};
Scene person_2m_at_60_degrees() {
  Scene s;
  s.pose.x = 1.0, s.pose.y = -0.5, s.pose.yaw = deg2rad(20.0), s.pose.height = 0.9;
  s.person.a = s.person.b = Eigen::Vector2d(s.pose.x + 2.0 * std::cos(deg2rad(60.0)),
                                            s.pose.y + 2.0 * std::sin(deg2rad(60.0)));
  s.person.width = 0.5, s.person.height = 1.7, s.person.grey = 30.0;
  return s;
}

TEST(People, PaintedWhereTheCylinderProjects) {
  // A person 2 m from the camera at world azimuth 60 degrees, the camera yaw 20 degrees: at
  // camera bearing 40 degrees (image angle sign * 40), between the radii of the feet and the
  // head; not 1.5 half-widths to the side, nor beyond the head.
  auto [cam, pose, p] = person_2m_at_60_degrees();
  const double r_feet = cam.radius_of_elevation(std::atan2(-0.9, 2.0));
  const double r_head = cam.radius_of_elevation(std::atan2(0.8, 2.0));
  const double half = std::asin(0.25 / 2.0);
  for (int sign : {1, -1}) {
    cam.bearing_sign = sign;
    cv::Mat1f img(480, 640, 200.0f);
    paint_people({p}, 0.0, cam, pose, img);
    const auto at = [&](double bearing, double r) {
      const double a = sign * bearing;
      return img(static_cast<int>(std::lround(cam.cy + r * std::sin(a))),
                 static_cast<int>(std::lround(cam.cx + r * std::cos(a))));
    };
    const double mid = 0.5 * (r_feet + r_head), b = deg2rad(40.0);
    EXPECT_NEAR(at(b, mid), 30.0, 0.5) << sign;                 // the person's centre line
    EXPECT_NEAR(at(b + 1.5 * half, mid), 200.0, 1e-3) << sign;  // beside them
    EXPECT_NEAR(at(b - 1.5 * half, mid), 200.0, 1e-3) << sign;
    EXPECT_NEAR(at(b, r_head + 3.0), 200.0, 1e-3) << sign;  // above the head
    EXPECT_NEAR(at(b, r_feet - 3.0), 200.0, 1e-3) << sign;  // below the feet
    EXPECT_LT(at(b + 0.8 * half, mid), 200.0) << sign;      // inside, near the side
  }
}

TEST(People, TheGroundTruthLeavesOutWhatTheyHide) {
  // A person 2 m away at world azimuth 0 (camera yaw 0): a line behind them at the same
  // bearing spanning the annulus keeps its longer piece above or below them; one spanning only
  // their height is gone; one in front of them, or beside them, is kept whole.
  CatadioptricCamera cam;
  CameraPose pose;
  Person p;
  p.a = p.b = Eigen::Vector2d(2.0, 0.0);
  p.width = 0.5, p.height = 1.7;
  const double r_feet = cam.radius_of_elevation(std::atan2(-0.9, 2.0));
  const double r_head = cam.radius_of_elevation(std::atan2(0.8, 2.0));
  std::vector<VisibleLine> lines(4);
  lines[0] = {1, 0.01, cam.r_min, cam.r_max, 5.0};     // behind, the whole annulus
  lines[1] = {2, -0.02, r_feet + 2, r_head - 2, 4.0};  // behind, within their height
  lines[2] = {3, 0.0, cam.r_min, cam.r_max, 1.0};      // in front
  lines[3] = {4, 0.3, cam.r_min, cam.r_max, 5.0};      // beside
  hide_lines({p}, 0.0, cam, pose, 2.0, lines);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].line_id, 1);
  const double below = r_feet - cam.r_min, above = cam.r_max - r_head;
  EXPECT_NEAR(lines[0].r_outer - lines[0].r_inner, std::max(below, above), 1e-9);
  EXPECT_EQ(lines[1].line_id, 3);
  EXPECT_EQ(lines[1].r_outer - lines[1].r_inner, cam.r_max - cam.r_min);
  EXPECT_EQ(lines[2].line_id, 4);
}

TEST(People, TheirSidesAreWrittenAsOccluderEdges) {
  // The person of PaintedWhereTheCylinderProjects: sides at 40 -+ asin(0.25 / 2) degrees.
  const auto [cam, pose, p] = person_2m_at_60_degrees();
  Person behind = p;  // walked through the camera: not seen, no edges
  behind.a = behind.b = Eigen::Vector2d(pose.x, pose.y);
  const auto edges = occluder_edges({behind, p}, 0.0, cam, pose);
  ASSERT_EQ(edges.size(), 2u);
  const double half = std::asin(0.25 / 2.0);
  EXPECT_EQ(edges[0].first, 1);
  EXPECT_NEAR(edges[0].second, deg2rad(40.0) - half, 1e-12);
  EXPECT_NEAR(edges[1].second, deg2rad(40.0) + half, 1e-12);
}

TEST(People, DrawnInsideTheRoomAndReproducible) {
  const World w = world_preset("office");
  const auto a = draw_people(5, 3, w), b = draw_people(5, 3, w);
  ASSERT_EQ(a.size(), 5u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].a, b[i].a);
    for (const Eigen::Vector2d& q : {a[i].a, a[i].b}) {
      EXPECT_GT(q.x(), -1.0 + 0.5 - 1e-9);  // the office spans x -1..10, y -1.5..5.5
      EXPECT_LT(q.x(), 10.0 - 0.5 + 1e-9);
      EXPECT_GT(q.y(), -1.5 + 0.5 - 1e-9);
      EXPECT_LT(q.y(), 5.5 - 0.5 + 1e-9);
    }
  }
  EXPECT_TRUE(draw_people(0, 3, w).empty());
}

}  // namespace
}  // namespace omnivert::sim
