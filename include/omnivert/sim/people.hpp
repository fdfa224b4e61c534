#pragma once
// People walking through the scene: moving occluders (docs/simulator.md#nuisances). Each walks
// back and forth along a straight segment inside the room at walking speed; in the image a
// person is an upright cylinder from the floor to their height, painted over the rendering
// with sub-pixel coverage, so the lines behind are hidden and the person's own two sides are
// vertical edges of no world line. The ground truth (lines.csv) leaves out what they hide
// (hide_lines).

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "omnivert/sim/camera_model.hpp"
#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

struct Person {
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::UnitX();  // path ends [m]
  double speed = 1.2;                                                         // [m/s]
  double phase = 0.0;    // where on the walk at t = 0: fraction of a return trip
  double width = 0.45;   // [m]
  double height = 1.75;  // [m]
  double grey = 70.0;    // clothing grey level
};

// `count` people drawn from `seed`: paths between points of the room (the walls' bounding box
// less 0.5 m), walking at 0.8-1.5 m/s.
std::vector<Person> draw_people(int count, std::uint64_t seed, const World& world);

// Where a person is at time t [s].
Eigen::Vector2d person_position(const Person& p, double t);

// The ground truth without what the people hide at time t: a line behind a person (further
// than they are, within their width) keeps the longer piece of its radial extent above or below
// them, and is left out when that is shorter than min_line_px or nothing is left.
void hide_lines(const std::vector<Person>& people,
                double t,
                const CatadioptricCamera& camera,
                const CameraPose& pose,
                double min_line_px,
                std::vector<VisibleLine>& lines);

// The bearings (radians, the camera's) of the two sides of each person seen at time t, with the
// person's index: vertical edges of no world line (ground_truth/occluders.csv).
std::vector<std::pair<int, double>> occluder_edges(const std::vector<Person>& people,
                                                   double t,
                                                   const CatadioptricCamera& camera,
                                                   const CameraPose& pose);

// Paints the people at time t, seen from `pose`, over a rendering (upright camera; far people
// first, so that nearer ones hide them).
void paint_people(const std::vector<Person>& people,
                  double t,
                  const CatadioptricCamera& camera,
                  const CameraPose& pose,
                  cv::Mat1f& image);

}  // namespace omnivert::sim
