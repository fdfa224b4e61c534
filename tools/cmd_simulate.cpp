// omnivert simulate: renders a catadioptric dataset with ground truth (docs/simulator.md).

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "core/progress.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/sim/simulator.hpp"

namespace omnivert::cli {

namespace {

struct SimulateArgs {
  std::string world = "corridor";
  std::string trajectory = "paper";
  std::string out;
  bool force = false;
  sim::SimConfig cfg;
  std::string wheel_unit = "meters";
  std::vector<double> center;
  std::vector<double> ticks_per_meter;
  std::vector<double> reflection;
  std::vector<double> reflection_radii;
  std::vector<double> laser_pose;
  double light_azimuth_deg = 0.0;
};

// World, trajectory, output and frames.
void add_run_options(CLI::App* cmd, SimulateArgs& a) {
  sim::SimConfig& c = a.cfg;
  cmd->add_option("--world",
                  a.world,
                  "World: corridor, office, hall, random (drawn from --seed), random:SEED, or a "
                  "YAML file")
      ->capture_default_str();
  cmd->add_option(
         "--trajectory", a.trajectory, "Trajectory: paper, zigzag, straight, tour, or a YAML file")
      ->capture_default_str();
  cmd->add_option("--out", a.out, "Output dataset directory (must not exist)")->required();
  cmd->add_flag("--force", a.force, "Replace the output directory if it exists");
  cmd->add_option("--seed", c.seed, "Seed of every random draw (noise)")->capture_default_str();
  cmd->add_option("--frames", c.max_frames, "At most this many frames (0: whole trajectory)")
      ->check(kNonNegative);
  cmd->add_option("--rate", c.frame_rate, "Frame rate [Hz]")
      ->capture_default_str()
      ->check(kPositive);
}

// Camera and mounting.
void add_camera_options(CLI::App* cmd, SimulateArgs& a) {
  sim::SimConfig& c = a.cfg;
  cmd->add_option("--width", c.camera.width, "Image width [px]")->capture_default_str();
  cmd->add_option("--height", c.camera.height, "Image height [px]")->capture_default_str();
  cmd->add_option("--center", a.center, "Mirror centre cx cy [px] (default 321.37 238.81)")
      ->expected(2);
  cmd->add_option("--xi", c.camera.xi, "Unified model mirror parameter xi")->capture_default_str();
  cmd->add_option("--gamma", c.camera.gamma, "Unified model focal length gamma [px]")
      ->capture_default_str();
  cmd->add_option("--r-min", c.camera.r_min, "Valid annulus inner radius [px]")
      ->capture_default_str();
  cmd->add_option("--r-max", c.camera.r_max, "Valid annulus outer radius [px]")
      ->capture_default_str();
  cmd->add_option(
         "--bearing-sign", c.camera.bearing_sign, "+1: beta = a; -1: mirrored image (beta = -a)")
      ->check(CLI::IsMember({1, -1}))
      ->capture_default_str();
  cmd->add_option("--tilt-deg",
                  c.camera.tilt_deg,
                  "Tilt of the mirror axis from the vertical [deg], 0..10 (docs/simulator.md)")
      ->capture_default_str();
  cmd->add_option("--tilt-direction-deg",
                  c.camera.tilt_direction_deg,
                  "Camera bearing the tilted axis leans towards [deg]")
      ->capture_default_str();
  cmd->add_option("--camera-height", c.camera_height, "Camera centre above the floor [m]")
      ->capture_default_str();
  cmd->add_option("--phi", c.extrinsics.phi, "Extrinsics phi [rad]")->capture_default_str();
  cmd->add_option("--rho", c.extrinsics.rho, "Extrinsics rho [m]")->capture_default_str();
  cmd->add_option("--psi", c.extrinsics.psi, "Extrinsics psi [rad]")->capture_default_str();
}

// Wheels.
void add_wheel_options(CLI::App* cmd, SimulateArgs& a) {
  sim::SimConfig& c = a.cfg;
  cmd->add_option("--wheel-rate", c.wheel.rate_hz, "Wheel data rate [Hz]")
      ->capture_default_str()
      ->check(kPositive);
  cmd->add_option("--wheel-base", c.wheel.wheel_base, "Nominal wheel base e [m]")
      ->capture_default_str();
  cmd->add_option(
         "--odometry-k", c.wheel.odometry_k, "Chong-Kleeman K [m]: increment variance K|d|")
      ->capture_default_str()
      ->check(kNonNegative);
  cmd->add_option("--radius-error-left",
                  c.wheel.radius_error_left,
                  "Systematic scale error of the left wheel (0.01: reports 1% too much)");
  cmd->add_option("--radius-error-right",
                  c.wheel.radius_error_right,
                  "Systematic scale error of the right wheel");
  cmd->add_option(
      "--wheel-base-error", c.wheel.wheel_base_error, "True wheel base = nominal * (1 + this)");
  cmd->add_option("--wheel-unit", a.wheel_unit, "meters or ticks")
      ->check(CLI::IsMember({"meters", "ticks"}))
      ->capture_default_str();
  cmd->add_option(
         "--ticks-per-meter", a.ticks_per_meter, "Ticks per meter, left [right] (default 20000)")
      ->expected(1, 2)
      ->check(kPositive);
  cmd->add_option("--counter-bits", c.wheel.counter_bits, "Tick counters wrap at 2^bits (0: never)")
      ->check(CLI::Range(0, 62));
}

// Image sensor.
void add_image_sensor_options(CLI::App* cmd, SimulateArgs& a) {
  sim::SimConfig& c = a.cfg;
  cmd->add_option("--noise", c.image.noise_sigma, "Image noise sigma [grey levels]")
      ->capture_default_str()
      ->check(kNonNegative);
  cmd->add_option("--gain-flicker", c.image.gain_flicker, "Per-frame gain sigma (relative)")
      ->capture_default_str()
      ->check(kNonNegative);
  cmd->add_option("--exposure", c.image.exposure, "Mean gain; > 1 saturates bright areas")
      ->capture_default_str()
      ->check(kPositive);
  cmd->add_option("--blur", c.image.blur_sigma, "Gaussian blur sigma [px]")
      ->capture_default_str()
      ->check(kNonNegative);
  cmd->add_option(
         "--exposure-time",
         c.image.exposure_time,
         "Motion blur: each image averaged over the robot's motion during this exposure [s]")
      ->capture_default_str()
      ->check(kNonNegative);
  cmd->add_option("--jpeg-quality",
                  c.image.jpeg_quality,
                  "Write the images as JPEG at this quality (1-100); 0: PNG, lossless")
      ->capture_default_str()
      ->check(CLI::Range(0, 100));
  cmd->add_option("--vignetting", c.image.vignetting, "The lens's gain lost at the rim (0..1)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.99));
  cmd->add_option("--light-gradient",
                  c.image.light_gradient,
                  "Light across the room: gain 1 + G cos(azimuth - light azimuth); 1/3 is a "
                  "factor of 2")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.99));
  cmd->add_option("--people", c.people, "People walking through the scene (moving occluders)")
      ->capture_default_str()
      ->check(CLI::Range(0, 50));
  cmd->add_option(
         "--light-azimuth", a.light_azimuth_deg, "World direction of the brightest light [deg]")
      ->capture_default_str();
}

// Struts, the robot's reflection and the ground-truth mask (docs/simulator.md).
void add_overlay_options(CLI::App* cmd, SimulateArgs& a) {
  sim::RobotOverlay& o = a.cfg.overlay;
  const std::string g = "Struts and reflection";
  cmd->add_option("--strut",
                  o.strut_angles_deg,
                  "Draw a dark mount strut from the rim inward at these image angles [deg]")
      ->group(g);
  cmd->add_option("--strut-width", o.strut_width_px, "Strut width [px]")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 100.0))
      ->group(g);
  cmd->add_option("--strut-inner",
                  o.strut_inner_px,
                  "Inner end of the struts [px from the centre] (0: r_min)")
      ->capture_default_str()
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--strut-grey", o.strut_grey, "Grey level of the struts")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 255.0))
      ->group(g);
  cmd->add_option(
         "--reflection",
         a.reflection,
         "Draw the robot's reflection: a sector at image angle ANGLE [deg], WIDTH [deg] wide")
      ->expected(2)
      ->group(g);
  cmd->add_option("--reflection-radii",
                  a.reflection_radii,
                  "Inner and outer radius of the reflection [px] (default: r_min - 3 to r_min + "
                  "30% of the annulus)")
      ->expected(2)
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--reflection-grey", o.reflection_grey, "Grey level of the reflection")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 255.0))
      ->group(g);
  cmd->add_flag(
         "--write-mask",
         o.write_mask,
         "Write the ground-truth mask cam0/mask.png and 'mask: mask.png' in cam0/sensor.yaml")
      ->group(g);
  cmd->add_option("--mask-margin", o.mask_margin_px, "The mask covers this much more [px]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 20.0))
      ->group(g);
}

// The 2D laser scanner (laser0/), off unless --laser.
void add_laser_options(CLI::App* cmd, SimulateArgs& a) {
  sim::LaserConfig& l = a.cfg.laser;
  const std::string g = "Laser scanner (laser0/)";
  cmd->add_flag("--laser", l.enabled, "Write laser0/: a 2D laser scanner's scans")->group(g);
  cmd->add_option(
         "--laser-pose", a.laser_pose, "Scanner pose on the robot: x [m], y [m], yaw [rad]")
      ->expected(3)
      ->group(g);
  cmd->add_option("--laser-height", l.height, "Height of the scan plane [m]")
      ->capture_default_str()
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--laser-rate", l.rate_hz, "Scans per second [Hz]")
      ->capture_default_str()
      ->check(kPositive)
      ->group(g);
  cmd->add_option("--laser-noise", l.noise_sigma, "Range noise sigma [m]")
      ->capture_default_str()
      ->check(kNonNegative)
      ->group(g);
  cmd->add_option("--laser-max-range", l.range_max, "Maximum range [m] (no return beyond)")
      ->capture_default_str()
      ->check(kPositive)
      ->group(g);
}

// The world by name or file; `random` (the run's seed) or `random:SEED`: a room drawn around
// the trajectory's path (sim::random_world).
sim::World load_world_for(const std::string& name,
                          const sim::Trajectory& trajectory,
                          std::uint64_t run_seed) {
  if (name != "random" && name.rfind("random:", 0) != 0) return sim::load_world(name);
  std::uint64_t seed = run_seed;
  if (name.size() > 7) {
    const std::string n = name.substr(7);
    char* end = nullptr;
    seed = std::strtoull(n.c_str(), &end, 10);
    if (n.empty() || *end != '\0' || n[0] == '-')
      throw InputError("--world " + name + ": the seed after 'random:' must be a whole number");
  }
  const std::vector<sim::MotionPiece> motion = trajectory.pieces(sim::Pose2::Zero());
  std::vector<Eigen::Vector2d> path;
  const double end = sim::duration(motion);
  for (double t = 0.0; t <= end + 0.05; t += 0.05)
    path.push_back(sim::pose_at(motion, t).head<2>());
  return sim::random_world(seed, path);
}

void run_simulate(SimulateArgs& a) {
  sim::SimConfig& cfg = a.cfg;
  cfg.wheel.ticks = a.wheel_unit == "ticks";
  if (a.center.size() == 2) {
    cfg.camera.cx = a.center[0];
    cfg.camera.cy = a.center[1];
  }
  if (!a.ticks_per_meter.empty()) {
    cfg.wheel.ticks_per_meter_left = a.ticks_per_meter.front();
    cfg.wheel.ticks_per_meter_right = a.ticks_per_meter.back();
  }
  if (a.reflection.size() == 2) {
    cfg.overlay.reflection_angle_deg = a.reflection[0];
    cfg.overlay.reflection_width_deg = a.reflection[1];
  }
  if (a.reflection_radii.size() == 2) {
    cfg.overlay.reflection_r_inner_px = a.reflection_radii[0];
    cfg.overlay.reflection_r_outer_px = a.reflection_radii[1];
  }
  if (a.laser_pose.size() == 3) {
    cfg.laser.x = a.laser_pose[0];
    cfg.laser.y = a.laser_pose[1];
    cfg.laser.yaw = a.laser_pose[2];
  }
  cfg.image.light_azimuth = deg2rad(a.light_azimuth_deg);
  const sim::Trajectory trajectory = sim::load_trajectory(a.trajectory);
  const sim::World world = load_world_for(a.world, trajectory, cfg.seed);
  std::unique_ptr<Progress> progress;
  const sim::SimSummary s =
      sim::simulate(world, trajectory, a.cfg, a.out, a.force, [&progress](int done, int total) {
        if (!progress)
          progress = std::make_unique<Progress>("simulate", static_cast<std::size_t>(total));
        progress->update(static_cast<std::size_t>(done));
      });
  if (progress) progress->finish();
  std::printf(
      "wrote %s: %d frames, %d wheel samples, %.2f m driven, %.1f ground-truth lines per "
      "frame, %.1f s\n",
      a.out.c_str(),
      s.frames,
      s.wheel_samples,
      s.distance,
      s.mean_lines,
      s.seconds);
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "simulate",
      "Render a dataset (images, wheel odometry, ground truth) of a robot driving through a world");
  auto args = std::make_shared<SimulateArgs>();
  add_run_options(cmd, *args);
  add_camera_options(cmd, *args);
  add_wheel_options(cmd, *args);
  add_image_sensor_options(cmd, *args);
  add_overlay_options(cmd, *args);
  add_laser_options(cmd, *args);
  cmd->callback([args]() { run_simulate(*args); });
}

}  // namespace omnivert::cli
