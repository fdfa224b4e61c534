#pragma once
// Renders catadioptric images of a World (camera_model.hpp, world.hpp) and lists the world
// vertical lines each image shows (the ground truth of Sec. 2's extraction).
//
// Method. With the mirror axis vertical, a pixel's azimuth fixes a vertical half-plane and its
// radius fixes the elevation. Per camera, a look-up table holds each pixel's bearing,
// azimuthal footprint and elevation. Per frame, the azimuths of all world vertical edges are
// sorted: between two consecutive ones the sequence of walls a horizontal ray meets does not
// change, so one ray cast per interval lists them. A pixel then only intersects those few
// walls and takes the first one whose height range contains the pixel's hit height.
//
// Anti-aliasing. Each pixel integrates a box footprint: 1 px tangentially (azimuth
// [a - 1/(2r), a + 1/(2r)]) and 1 px radially. The footprint is split exactly at the
// vertical edges it contains (analytic coverage in azimuth), so a vertical edge lands at its
// exact sub-pixel bearing; horizontal texture edges, wall tops and bottoms are box-filtered
// in height; floor and ceiling tiles are blended over the footprint.
//
// Tilt. With CatadioptricCamera::tilt_deg != 0 the image is that of an upright camera
// warped to the tilted one (sim/tilt_warp.hpp, docs/simulator.md#tilt); visible_lines() keeps
// the upright bearings, the ones eq. (16)-(17) predict, and render_reference() draws upright.

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/sim/camera_model.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

class TiltWarp;

// The camera's pose in the world: centre (x, y) [m], height above the floor [m], and the
// heading of the camera x-axis [rad] (theta_R + phi + psi, docs/theory/conventions.md).
struct CameraPose {
  double x = 0, y = 0, yaw = 0;
  double height = 0.9;
};

// One world vertical line in one image (ground_truth/lines.csv).
struct VisibleLine {
  int line_id = 0;     // VerticalEdge::id
  double bearing = 0;  // camera bearing beta [rad], (-pi, pi] (eq. 16-17)
  double r_inner = 0;  // radial extent of its visible part inside r_min..r_max [px]
  double r_outer = 0;
  double distance = 0;  // horizontal distance from the camera centre [m]
};

class Renderer {
 public:
  Renderer(const CatadioptricCamera& camera, const World& world);

  // Renders one noise-free image: grey levels (nominally 0..255, not clipped), CV_32F.
  void render(const CameraPose& pose, cv::Mat1f& image) const;
  cv::Mat1f render(const CameraPose& pose) const;

  // The plain reference for tests and benchmarks: every pixel casts `samples` rays spread
  // over its azimuthal footprint against every wall (no edge intervals, no analytic
  // coverage). Same textures. Slow.
  void render_reference(const CameraPose& pose, int samples, cv::Mat1f& image) const;

  // The vertical edges visible from `pose`, occlusion by nearer walls considered, each with
  // the part of it inside the valid annulus; only edges with at least `min_length_px`
  // visible radial pixels.
  std::vector<VisibleLine> visible_lines(const CameraPose& pose, double min_length_px = 2.0) const;

  const std::vector<VerticalEdge>& edges() const { return edges_; }
  const CatadioptricCamera& camera() const { return camera_; }
  const World& world() const { return world_; }

  // Radii between which the world is drawn; inside: the camera's reflection, outside: rim.
  double world_r_in() const { return camera_.self_radius(); }
  double world_r_out() const { return camera_.rim_radius(); }

 private:
  struct FrameState;
  float shade(const FrameState& f,
              int interval,
              double dx,
              double dy,
              double tan_el,
              double dtan,
              double halfw) const;
  float shade_hits(const FrameState& f,
                   const int* hits_begin,
                   const int* hits_end,
                   double dx,
                   double dy,
                   double tan_el,
                   double dtan,
                   double halfw) const;
  void setup_walls(const CameraPose& pose, FrameState& f) const;
  float wall_texture(int wall, double s, double z, double ds, double dz) const;
  float plane_texture(const Plane& p, double x, double y, double footprint, bool ceiling) const;

  CatadioptricCamera camera_;
  World world_;
  std::shared_ptr<const TiltWarp> tilt_;  // set when the camera is tilted
  std::vector<VerticalEdge> edges_;
  std::vector<WallTexture> textures_;
  std::vector<double> wall_top_;
  std::vector<std::vector<std::vector<int>>> panel_index_;  // wall -> 0.25 m cell -> panels

  // Per-pixel look-up table (pixels whose footprint touches the world annulus).
  std::vector<int> px_index_;
  std::vector<float> px_beta_, px_cos_, px_sin_, px_halfw_, px_tan_, px_dtan_, px_weight_;
  cv::Mat1f background_;  // rim and self-reflection, drawn where px_weight_ < 1
};

}  // namespace omnivert::sim
