#pragma once
// Indoor worlds for the simulator: vertical textured walls (each a two-sided rectangle
// standing on a 2-D segment), a floor and a ceiling. Every world vertical line the pipeline
// can see (Sec. 2) is a vertical edge of this world: a wall end, the side of a panel (door,
// window, poster) or a full-height change of paint. Boxes (furniture, pillars) are four walls.
//
// Worlds are small YAML files (format in docs/simulator.md) or built-in presets: `corridor`
// (a corridor with doors), `office` (furniture and pillars), `hall` (repetitive windows and
// pillars: the paper's failure case, Sec. 9.1).
//
// Restrictions: walls meet only at their end points (they do not cross); texture changes
// along a wall (strips, panel sides) are the only vertical discontinuities of a wall.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace omnivert::sim {

enum class Pattern { kFlat, kStripes, kWave };

// A rectangle on a wall: s0..s1 along the wall (metres from the wall's `from` end), z0..z1
// in height. Its vertical sides are world vertical lines of height z0..z1 (partial height).
struct Panel {
  double s0 = 0, s1 = 0, z0 = 0, z1 = 0;
  double intensity = 128;  // grey level 0..255
  Pattern pattern = Pattern::kFlat;
  double period = 0.2;      // stripes / wave period [m]
  double angle_deg = 0.0;   // wave direction: 0 = varies along the wall, 90 = with height
  double amplitude = 20.0;  // stripes / wave amplitude [grey levels]
};

// A full-height change of paint: s0..s1 along the wall has another base intensity.
struct Strip {
  double s0 = 0, s1 = 0;
  double intensity = 128;
};

struct Wall {
  Eigen::Vector2d from = Eigen::Vector2d::Zero();
  Eigen::Vector2d to = Eigen::Vector2d::UnitX();
  double z0 = 0.0;
  double z1 = -1.0;  // < 0: up to the ceiling
  double intensity = 150;
  double texture = 8.0;         // amplitude (std) of the smooth noise texture [grey levels]
  double texture_scale = 0.05;  // feature size of the noise texture [m]
  std::vector<Strip> strips;
  std::vector<Panel> panels;

  double length() const { return (to - from).norm(); }
};

// Floor or ceiling: square tiles of side `tile` [m], each with its own grey level around
// `intensity` (+- contrast).
struct Plane {
  double intensity = 100;
  double contrast = 20;
  double tile = 0.5;
};

// A world vertical line: the position of a vertical edge and its height range.
struct VerticalEdge {
  int id = 0;  // stable: the index in World::edges()
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double z0 = 0, z1 = 0;
};

struct World {
  std::string name = "world";
  double height = 2.6;     // ceiling height [m]
  std::uint64_t seed = 1;  // seed of the wall noise textures
  Plane floor{90, 25, 0.5};
  Plane ceiling{210, 12, 0.6};
  std::vector<Wall> walls;
  // Default robot start pose (x [m], y [m], theta [rad]) for the trajectory presets, with
  // at least 6 m x 2 m of free space ahead and to the left.
  Eigen::Vector3d start = Eigen::Vector3d::Zero();

  // Adds an axis-aligned-in-its-own-frame box (4 walls, faces shaded differently).
  void add_box(const Eigen::Vector2d& center,
               const Eigen::Vector2d& size,
               double yaw,
               double box_height,
               double intensity,
               double texture = 6.0);
  // Wall top height (resolves z1 < 0 to the ceiling).
  double top(const Wall& w) const { return w.z1 < 0 ? height : std::min(w.z1, height); }
  // All vertical edges: wall ends, strip boundaries, panel sides; edges at the same place
  // (within 1 mm) are one edge with the union of the height ranges.
  std::vector<VerticalEdge> edges() const;
  // Checks the world; returns an empty string or what is wrong.
  std::string validate() const;
};

// Names of the built-in worlds.
std::vector<std::string> world_presets();
// A built-in world by name; throws InputError for an unknown name.
World world_preset(const std::string& name);
// A room drawn from `seed` around a robot path (points of the robot centre [m], the path
// starting at the origin heading along x: World::start is zero): its size (a narrow corridor to
// a wide hall), height, floor and ceiling, wall pieces with their paint, noise texture (coarse
// to fine), doors, windows, posters, paint strips and lattices of identical slats, and
// pillars and furniture kept 0.6 m from the path (`simulate --world random[:SEED]`).
World random_world(std::uint64_t seed, const std::vector<Eigen::Vector2d>& path);
// A preset name or a YAML file. Throws InputError (file, line, problem) on bad input.
World load_world(const std::string& name_or_file);
// Writes a world as YAML (the format load_world reads).
void save_world(const World& world, const std::string& path);

// The smooth noise texture of one wall, baked once: a raster of 2 cm texels.
class WallTexture {
 public:
  WallTexture() = default;
  WallTexture(const Wall& wall, double wall_height, std::uint64_t seed);
  // Noise value at (s, z), bilinear.
  float noise(double s, double z) const;

 private:
  cv::Mat1f raster_;
  double texel_ = 0.02;
};

}  // namespace omnivert::sim
