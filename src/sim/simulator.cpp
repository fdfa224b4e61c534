#include "omnivert/sim/simulator.hpp"

#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/writer.hpp"
#include "omnivert/sim/map_picture.hpp"
#include "omnivert/sim/people.hpp"

namespace omnivert::sim {

namespace fs = std::filesystem;

CameraPose camera_pose(const Pose2& robot, const Extrinsics& x, double camera_height) {
  const double c = std::cos(robot.z()), s = std::sin(robot.z());
  const double ox = x.rho * std::cos(x.phi), oy = x.rho * std::sin(x.phi);
  CameraPose p;
  p.x = robot.x() + c * ox - s * oy;
  p.y = robot.y() + s * ox + c * oy;
  p.yaw = robot.z() + x.phi + x.psi;
  p.height = camera_height;
  return p;
}

namespace {

double distance_to_segment(const Eigen::Vector2d& p,
                           const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d u = b - a;
  const double t = std::clamp((p - a).dot(u) / u.squaredNorm(), 0.0, 1.0);
  return (a + t * u - p).norm();
}

FILE* open_or_throw(const fs::path& p) {
  FILE* f = std::fopen(p.c_str(), "w");
  if (!f)
    throw InputError(p.string(), 0, "cannot write (disk full, or a folder that is not writable?)");
  return f;
}

struct FileCloser {
  FILE* f;
  ~FileCloser() {
    if (f) std::fclose(f);
  }
};

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p);
  out << text;
  if (!out)
    throw InputError(p.string(), 0, "cannot write (disk full, or a folder that is not writable?)");
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

std::string free_space_violation(const World& world,
                                 const std::vector<MotionPiece>& motion,
                                 double t_end,
                                 double clearance) {
  for (double t = 0.0; t <= t_end + 1e-9; t += 0.02) {
    const Pose2 p = pose_at(motion, t);
    for (std::size_t i = 0; i < world.walls.size(); ++i) {
      const Wall& w = world.walls[i];
      if (distance_to_segment(p.head<2>(), w.from, w.to) < clearance) {
        char where[200];
        std::snprintf(
            where,
            sizeof where,
            "at t = %.2f s the robot (x = %.2f, y = %.2f) comes within %.2f m of wall %zu "
            "of world '%s'",
            t,
            p.x(),
            p.y(),
            clearance,
            i + 1,
            world.name.c_str());
        return where;
      }
    }
  }
  return {};
}

namespace {

// Frame times: the first 10 ms after the start of the wheel data (so that every image
// timestamp falls between two wheel samples), then every 1/rate.
struct FrameTimes {
  std::int64_t step_ns = 0;
  std::int64_t first_offset_ns = 10'000'000;
  int count = 0;
  double time(int k) const { return static_cast<double>(first_offset_ns + k * step_ns) * 1e-9; }
  double last() const { return time(count - 1); }
};

FrameTimes frame_times(const SimConfig& cfg, double t_motion) {
  FrameTimes f;
  f.step_ns = std::llround(1e9 / cfg.frame_rate);
  // The last frame is at or after the end of the motion, so that it shows the final pose.
  f.count = static_cast<int>(std::ceil((t_motion * 1e9 - static_cast<double>(f.first_offset_ns)) /
                                       static_cast<double>(f.step_ns))) +
            1;
  f.count = std::max(f.count, 1);
  if (cfg.max_frames > 0) f.count = std::min(f.count, cfg.max_frames);
  return f;
}

// wheel0/data.csv: the wheel samples (50 Hz), covering every image.
void write_wheel_data(const fs::path& path,
                      const WheelSamples& wheels,
                      const WheelConfig& wc,
                      std::int64_t t0) {
  dataset::WheelCsvWriter csv(path.string(),
                              wc.ticks ? dataset::WheelUnit::kTicks : dataset::WheelUnit::kMeters);
  for (std::size_t i = 0; i < wheels.t.size(); ++i) {
    const std::int64_t ts = t0 + std::llround(wheels.t[i] * 1e9);
    if (wc.ticks) {
      csv.add_ticks(ts,
                    to_ticks(wheels.left[i], wc.ticks_per_meter_left, wc.counter_bits),
                    to_ticks(wheels.right[i], wc.ticks_per_meter_right, wc.counter_bits));
    } else {
      csv.add_meters(ts, wheels.left[i], wheels.right[i]);
    }
  }
  csv.close();
}

// wheel0/sensor.yaml.
void write_wheel_sensor(const fs::path& path, const WheelConfig& wc) {
  dataset::WheelSensor s;
  s.wheel_base = wc.wheel_base;
  s.unit = wc.ticks ? dataset::WheelUnit::kTicks : dataset::WheelUnit::kMeters;
  s.ticks_per_meter_left = wc.ticks_per_meter_left;
  s.ticks_per_meter_right = wc.ticks_per_meter_right;
  s.counter_bits = wc.counter_bits;
  s.odometry_k = wc.odometry_k;
  write_text(
      path,
      dataset::wheel_sensor_yaml(
          s, wc.rate_hz, "omnivert simulator: wheel encoders (dataset format: docs/simulator.md)"));
}

// cam0/sensor.yaml.
void write_camera_sensor(const fs::path& path,
                         const CatadioptricCamera& c,
                         double frame_rate,
                         bool with_mask) {
  std::string y = "# omnivert simulator: catadioptric camera, unified sphere model with the\n";
  y += "# mirror axis vertical: r = gamma cos(el) / (xi - sin(el)) (docs/simulator.md)\n";
  y += "model: unified\n";
  y += "resolution: [" + std::to_string(c.width) + ", " + std::to_string(c.height) + "]\n";
  y += "center: [" + fmt("%.9g", c.cx) + ", " + fmt("%.9g", c.cy) + "]\n";
  y += "r_min: " + fmt("%.9g", c.r_min) + "\n";
  y += "r_max: " + fmt("%.9g", c.r_max) + "\n";
  y += "bearing_sign: " + std::to_string(c.bearing_sign) + "\n";
  y += "rim_radius: " + fmt("%.9g", c.rim_radius()) +
       "   # dark beyond: the mirror's outer boundary\n";
  y += "xi: " + fmt("%.9g", c.xi) + "\n";
  y += "gamma: " + fmt("%.9g", c.gamma) + "\n";
  if (c.tilt_deg != 0.0) {
    y += "tilt_deg: " + fmt("%.9g", c.tilt_deg) + "   # true tilt of the mirror axis\n";
    y += "tilt_direction_deg: " + fmt("%.9g", c.tilt_direction_deg) +
         "   # camera bearing the axis leans towards (docs/theory/tilt.md)\n";
  }
  y += "rate_hz: " + fmt("%.9g", frame_rate) + "\n";
  if (with_mask) y += "mask: mask.png   # the struts and the robot's reflection: 0\n";
  write_text(path, y);
}

// ground_truth/extrinsics.yaml.
void write_extrinsics(const fs::path& path, const Extrinsics& x, double camera_height) {
  const double tx = x.rho * std::cos(x.phi), ty = x.rho * std::sin(x.phi);
  std::string y = "# Camera-to-odometry extrinsics (NOTES Sec. 1, Fig. 19): camera centre at\n";
  y += "# rho (cos phi, sin phi) in the robot frame, camera x-axis at phi + psi.\n";
  y += "phi: " + fmt("%.12g", x.phi) + "   # [rad]\n";
  y += "rho: " + fmt("%.12g", x.rho) + "   # [m]\n";
  y += "psi: " + fmt("%.12g", x.psi) + "   # [rad]\n";
  y += "# the same as T_base_cam = [Rz(yaw) | (x, y, z)]\n";
  y += "T_base_cam: {x: " + fmt("%.12g", tx) + ", y: " + fmt("%.12g", ty) +
       ", z: " + fmt("%.12g", camera_height) + ", yaw: " + fmt("%.12g", wrap_angle(x.phi + x.psi)) +
       "}\n";
  write_text(path, y);
}

// ground_truth/edges.csv: the world's vertical lines.
void write_edges(const fs::path& path, const Renderer& renderer) {
  FILE* f = open_or_throw(path);
  FileCloser closer{f};
  std::fprintf(f, "#line_id,x [m],y [m],z_bottom [m],z_top [m]\n");
  for (const VerticalEdge& e : renderer.edges()) {
    std::fprintf(f, "%d,%.6f,%.6f,%.4f,%.4f\n", e.id, e.p.x(), e.p.y(), e.z0, e.z1);
  }
}

// ground_truth/simulation.yaml: the settings of the simulation that wrote the dataset.
void write_simulation_settings(const fs::path& path,
                               const World& world,
                               const Trajectory& trajectory,
                               const SimConfig& cfg,
                               const Pose2& start,
                               int n_frames) {
  const WheelConfig& wc = cfg.wheel;
  const ImageSensor& s = cfg.image;
  std::string y = "# Settings of the simulation that wrote this dataset.\n";
  y += "seed: " + std::to_string(cfg.seed) + "\n";
  y += "world: " + world.name + "\n";
  y += "trajectory: " + trajectory.name + "\n";
  y += "start: [" + fmt("%.9g", start.x()) + ", " + fmt("%.9g", start.y()) + ", " +
       fmt("%.9g", start.z()) + "]\n";
  y += "frames: " + std::to_string(n_frames) + "\n";
  y += "frame_rate: " + fmt("%.9g", cfg.frame_rate) + "\n";
  y += "camera_height: " + fmt("%.9g", cfg.camera_height) + "\n";
  y += "true_wheel_base: " + fmt("%.9g", wc.true_wheel_base()) + "\n";
  y += "wheel_base_error: " + fmt("%.9g", wc.wheel_base_error) + "\n";
  y += "radius_error_left: " + fmt("%.9g", wc.radius_error_left) + "\n";
  y += "radius_error_right: " + fmt("%.9g", wc.radius_error_right) + "\n";
  y += "odometry_k: " + fmt("%.9g", wc.odometry_k) + "\n";
  y += "image_noise_sigma: " + fmt("%.9g", s.noise_sigma) + "\n";
  y += "gain_flicker: " + fmt("%.9g", s.gain_flicker) + "\n";
  y += "exposure: " + fmt("%.9g", s.exposure) + "\n";
  y += "blur_sigma: " + fmt("%.9g", s.blur_sigma) + "\n";
  y += "exposure_time: " + fmt("%.9g", s.exposure_time) + "\n";
  y += "exposure_samples: " + std::to_string(s.exposure_samples) + "\n";
  y += "jpeg_quality: " + std::to_string(s.jpeg_quality) + "\n";
  y += "vignetting: " + fmt("%.9g", s.vignetting) + "\n";
  y += "light_gradient: " + fmt("%.9g", s.light_gradient) + "\n";
  y += "light_azimuth: " + fmt("%.9g", s.light_azimuth) + "\n";
  y += "people: " + std::to_string(cfg.people) + "\n";
  y += "min_line_px: " + fmt("%.9g", cfg.min_line_px) + "\n";
  const RobotOverlay& o = cfg.overlay;
  if (!o.strut_angles_deg.empty()) {
    y += "struts_deg: [";
    for (std::size_t i = 0; i < o.strut_angles_deg.size(); ++i)
      y += (i ? ", " : "") + fmt("%.9g", o.strut_angles_deg[i]);
    y += "]\n";
    y += "strut_width_px: " + fmt("%.9g", o.strut_width_px) + "\n";
    y += "strut_inner_px: " + fmt("%.9g", o.strut_inner_px) + "\n";
    y += "strut_grey: " + fmt("%.9g", o.strut_grey) + "\n";
  }
  if (o.reflection_width_deg > 0) {
    y += "reflection: [" + fmt("%.9g", o.reflection_angle_deg) + ", " +
         fmt("%.9g", o.reflection_width_deg) + "]\n";
    y += "reflection_radii_px: [" + fmt("%.9g", o.reflection_r_inner_px) + ", " +
         fmt("%.9g", o.reflection_r_outer_px) + "]\n";
    y += "reflection_grey: " + fmt("%.9g", o.reflection_grey) + "\n";
  }
  if (o.write_mask) y += "mask_margin_px: " + fmt("%.9g", o.mask_margin_px) + "\n";
  if (const LaserConfig& l = cfg.laser; l.enabled) {
    y += "laser_pose: [" + fmt("%.9g", l.x) + ", " + fmt("%.9g", l.y) + ", " + fmt("%.9g", l.yaw) +
         "]\n";
    y += "laser_height: " + fmt("%.9g", l.height) + "\n";
    y += "laser_rate_hz: " + fmt("%.9g", l.rate_hz) + "\n";
    y += "laser_noise: " + fmt("%.9g", l.noise_sigma) + "\n";
    y += "laser_max_range: " + fmt("%.9g", l.range_max) + "\n";
  }
  if (cfg.camera.tilt_deg != 0.0) {
    y += "tilt_deg: " + fmt("%.9g", cfg.camera.tilt_deg) + "\n";
    y += "tilt_direction_deg: " + fmt("%.9g", cfg.camera.tilt_direction_deg) + "\n";
  }
  write_text(path, y);
}

// The noise-free image of the frame at time t: one render, or with a motion blur
// (ImageSensor::exposure_time) the mean of exposure_samples renders spread evenly over the
// exposure, each at the robot's pose of its instant.
void render_exposure(const Renderer& renderer,
                     const std::vector<MotionPiece>& motion,
                     const std::vector<Person>& people,
                     double t,
                     const SimConfig& cfg,
                     cv::Mat1f& out) {
  const ImageSensor& s = cfg.image;
  const auto render_at = [&](double ti, cv::Mat1f& img) {
    const CameraPose cam = camera_pose(pose_at(motion, ti), cfg.extrinsics, cfg.camera_height);
    renderer.render(cam, img);
    if (!people.empty()) paint_people(people, ti, cfg.camera, cam, img);
  };
  if (!(s.exposure_time > 0.0) || s.exposure_samples <= 1) {
    render_at(t, out);
    return;
  }
  cv::Mat1f one;
  for (int i = 0; i < s.exposure_samples; ++i) {
    render_at(t + s.exposure_time * ((i + 0.5) / s.exposure_samples - 0.5), one);
    if (i == 0)
      out = one.clone();
    else
      out += one;
  }
  out /= static_cast<float>(s.exposure_samples);
}

// The frames: cam0/data/*.png (or .jpg) and cam0/data.csv, with ground_truth/poses.csv and
// lines.csv.
void write_frames(const fs::path& dir,
                  Renderer& renderer,
                  const std::vector<MotionPiece>& motion,
                  const SimConfig& cfg,
                  const FrameTimes& times,
                  SimSummary& summary,
                  const std::function<void(int, int)>& progress) {
  const std::int64_t t0 = cfg.start_ns;
  const int n_frames = times.count;
  dataset::ImageCsvWriter fcam((dir / "cam0" / "data.csv").string());
  FILE* fpose = open_or_throw(dir / "ground_truth" / "poses.csv");
  FileCloser cpose{fpose};
  FILE* flines = open_or_throw(dir / "ground_truth" / "lines.csv");
  FileCloser clines{flines};
  std::fprintf(fpose, "#timestamp [ns],x [m],y [m],theta [rad]\n");
  std::fprintf(flines, "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],r_outer [px]\n");
  std::mt19937_64 image_rng(cfg.seed * 2 + 2);
  cv::Mat1f clean;
  cv::Mat1b img;
  const std::vector<int> png_params = {cv::IMWRITE_PNG_COMPRESSION, 3};
  long total_lines = 0;
  // Struts and reflection: static in the image, painted before the image sensor.
  const bool overlay = !cfg.overlay.empty();
  const OverlayPicture picture =
      overlay ? overlay_picture(cfg.overlay, cfg.camera) : OverlayPicture{};
  const std::vector<Person> people = draw_people(cfg.people, cfg.seed, renderer.world());
  // The people's sides: edges of no world line, for the evaluation (docs/dataset-format.md).
  FILE* foccluders =
      people.empty() ? nullptr : open_or_throw(dir / "ground_truth" / "occluders.csv");
  FileCloser coccluders{foccluders};
  if (foccluders) std::fprintf(foccluders, "#timestamp [ns],frame,occluder,bearing [rad]\n");
  Pose2 prev = pose_at(motion, times.time(0));
  for (int k = 0; k < n_frames; ++k) {
    const double t = times.time(k);
    const std::int64_t ts = t0 + times.first_offset_ns + k * times.step_ns;
    const Pose2 robot = pose_at(motion, t);
    summary.distance += (robot.head<2>() - prev.head<2>()).norm();
    prev = robot;
    const CameraPose cam = camera_pose(robot, cfg.extrinsics, cfg.camera_height);
    render_exposure(renderer, motion, people, t, cfg, clean);
    apply_lighting(clean,
                   cfg.image,
                   cfg.camera.cx,
                   cfg.camera.cy,
                   cfg.camera.r_max,
                   cfg.camera.bearing_sign,
                   cam.yaw);
    if (overlay) paint_overlay(picture, clean);
    apply_image_sensor(clean, cfg.image, image_rng, img);
    const bool jpeg = cfg.image.jpeg_quality > 0;
    const std::string name = std::to_string(ts) + (jpeg ? ".jpg" : ".png");
    const std::vector<int> jpeg_params = {cv::IMWRITE_JPEG_QUALITY, cfg.image.jpeg_quality};
    if (!cv::imwrite(
            (dir / "cam0" / "data" / name).string(), img, jpeg ? jpeg_params : png_params)) {
      throw InputError((dir / "cam0" / "data" / name).string(),
                       0,
                       "cannot write (disk full, or a folder that is not writable?)");
    }
    fcam.add(ts, name);
    std::fprintf(
        fpose, "%" PRId64 ",%.9f,%.9f,%.9f\n", ts, robot.x(), robot.y(), wrap_angle(robot.z()));
    std::vector<VisibleLine> lines = renderer.visible_lines(cam, cfg.min_line_px);
    hide_lines(people, t, cfg.camera, cam, cfg.min_line_px, lines);
    if (foccluders) {
      for (const auto& [person, bearing] : occluder_edges(people, t, cfg.camera, cam))
        std::fprintf(foccluders, "%" PRId64 ",%d,%d,%.9f\n", ts, k, person, bearing);
    }
    for (const VisibleLine& l : lines) {
      std::fprintf(flines,
                   "%" PRId64 ",%d,%d,%.9f,%.3f,%.3f\n",
                   ts,
                   k,
                   l.line_id,
                   l.bearing,
                   l.r_inner,
                   l.r_outer);
      ++total_lines;
    }
    if (progress) progress(k + 1, n_frames);
  }
  summary.mean_lines = static_cast<double>(total_lines) / n_frames;
  fcam.close();
  for (FILE* f : {fpose, flines, foccluders}) {
    if (f && std::ferror(f)) throw InputError(dir.string(), 0, "write error (disk full?)");
  }
}

// ground_truth/map.png: a top view of the world and the path, for people to look at.
void write_map(const fs::path& path,
               const World& world,
               const std::vector<MotionPiece>& motion,
               const SimConfig& cfg,
               double t_last) {
  std::vector<Pose2> path_poses;
  std::vector<Eigen::Vector2d> cams;
  for (double t = 0.0; t <= t_last + 1e-9; t += 0.1) {
    path_poses.push_back(pose_at(motion, t));
    const CameraPose c = camera_pose(path_poses.back(), cfg.extrinsics, cfg.camera_height);
    cams.emplace_back(c.x, c.y);
  }
  if (!cv::imwrite(path.string(), draw_map(world, path_poses, cams))) {
    throw InputError(
        path.string(), 0, "cannot write (disk full, or a folder that is not writable?)");
  }
}

void write_dataset(const World& world,
                   const Trajectory& trajectory,
                   const SimConfig& cfg,
                   const fs::path& dir,
                   SimSummary& summary,
                   const std::function<void(int, int)>& progress) {
  const Pose2 start = trajectory.has_start ? trajectory.start : Pose2(world.start);
  const std::vector<MotionPiece> motion = trajectory.pieces(start);
  const FrameTimes times = frame_times(cfg, duration(motion));
  const double t_last = times.last();

  // The robot must stay in the free space of the world.
  if (const std::string p = free_space_violation(world, motion, t_last, cfg.min_clearance);
      !p.empty()) {
    throw InputError("trajectory '" + trajectory.name + "' leaves the free space: " + p +
                     "; give the trajectory a 'start' or choose another world");
  }

  fs::create_directories(dir / "cam0" / "data");
  fs::create_directories(dir / "wheel0");
  fs::create_directories(dir / "ground_truth");

  std::mt19937_64 wheel_rng(cfg.seed * 2 + 1);
  const WheelSamples wheels = simulate_wheels(motion, t_last, cfg.wheel, wheel_rng);
  write_wheel_data(dir / "wheel0" / "data.csv", wheels, cfg.wheel, cfg.start_ns);
  summary.wheel_samples = static_cast<int>(wheels.t.size());
  write_wheel_sensor(dir / "wheel0" / "sensor.yaml", cfg.wheel);
  write_camera_sensor(
      dir / "cam0" / "sensor.yaml", cfg.camera, cfg.frame_rate, cfg.overlay.write_mask);
  if (cfg.overlay.write_mask) {
    const cv::Mat mask =
        overlay_mask(overlay_picture(cfg.overlay, cfg.camera), cfg.overlay.mask_margin_px);
    if (!cv::imwrite((dir / "cam0" / "mask.png").string(), mask)) {
      throw InputError((dir / "cam0" / "mask.png").string(),
                       0,
                       "cannot write (disk full, or a folder that is not writable?)");
    }
  }
  write_extrinsics(dir / "ground_truth" / "extrinsics.yaml", cfg.extrinsics, cfg.camera_height);
  save_world(world, (dir / "ground_truth" / "world.yaml").string());

  Renderer renderer(cfg.camera, world);
  write_edges(dir / "ground_truth" / "edges.csv", renderer);
  write_simulation_settings(
      dir / "ground_truth" / "simulation.yaml", world, trajectory, cfg, start, times.count);
  write_frames(dir, renderer, motion, cfg, times, summary, progress);
  if (cfg.laser.enabled) {
    std::mt19937_64 laser_rng(cfg.seed * 2 + 3);
    write_laser(dir.string(), world, motion, t_last, cfg.laser, cfg.start_ns, laser_rng);
  }
  write_map(dir / "ground_truth" / "map.png", world, motion, cfg, t_last);
  summary.frames = times.count;
}

}  // namespace

SimSummary simulate(const World& world,
                    const Trajectory& trajectory,
                    const SimConfig& cfg,
                    const std::string& out_dir,
                    bool overwrite,
                    const std::function<void(int, int)>& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  if (const std::string p = cfg.camera.validate(); !p.empty()) throw InputError("camera: " + p);
  if (const std::string p = world.validate(); !p.empty())
    throw InputError("world '" + world.name + "': " + p);
  if (const std::string p = trajectory.validate(); !p.empty()) {
    throw InputError("trajectory '" + trajectory.name + "': " + p);
  }
  if (!(cfg.frame_rate > 0) || !(cfg.wheel.rate_hz > 0)) throw InputError("rates must be positive");
  if (std::string why; !cfg.overlay.IsValid(&why)) throw InputError("overlay: " + why);
  if (cfg.people < 0 || cfg.people > 50) throw InputError("people must be in 0..50");
  if (const std::string p = cfg.image.validate(); !p.empty())
    throw InputError("image sensor: " + p);
  if (cfg.laser.enabled) {
    if (const std::string p = cfg.laser.validate(); !p.empty()) throw InputError("laser: " + p);
  }
  if (cfg.wheel.odometry_k < 0) throw InputError("odometry_k must not be negative");
  if (!(cfg.wheel.wheel_base > 0) || !(cfg.wheel.true_wheel_base() > 0)) {
    throw InputError("the wheel base must be positive");
  }
  if (cfg.wheel.ticks &&
      (!(cfg.wheel.ticks_per_meter_left > 0) || !(cfg.wheel.ticks_per_meter_right > 0))) {
    throw InputError("ticks per meter must be positive");
  }
  if (cfg.wheel.counter_bits < 0 || cfg.wheel.counter_bits > 62) {
    throw InputError("counter_bits must be in 0..62");
  }
  if (!(cfg.camera_height > 0) || !(cfg.camera_height < world.height)) {
    throw InputError("the camera height must lie between the floor and the ceiling of world '" +
                     world.name + "' (0 to " + std::to_string(world.height) + " m)");
  }

  // "run/" names the folder run: its temporary sibling must not lie inside it.
  fs::path out = fs::path(out_dir).lexically_normal();
  if (!out.has_filename() && out.has_parent_path()) out = out.parent_path();
  std::error_code ec;
  if (fs::exists(out, ec) && !overwrite) {
    throw InputError(out.string(), 0, "already exists (use --force to replace it)");
  }
  if (overwrite) dataset::check_replaceable(out);
  fs::path parent = out.parent_path();
  if (parent.empty()) parent = ".";
  fs::create_directories(parent);
  const fs::path tmp = parent / (out.filename().string() + ".partial-" + std::to_string(cfg.seed));
  fs::remove_all(tmp, ec);
  SimSummary summary;
  try {
    write_dataset(world, trajectory, cfg, tmp, summary, progress);
    dataset::replace_folder(tmp, out);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return summary;
}

}  // namespace omnivert::sim
