// The check by eye as a job (paper Sec. 9.2, Figs. 23 and 26): the references of each frame,
// the corner-to-line offsets for two mountings, the picture and its report.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/pipeline/reprojection.hpp"
#include "omnivert/viz/reprojection_plot.hpp"

namespace omnivert::pipeline {

namespace fs = std::filesystem;

const char* to_string(ReferenceSource s) {
  switch (s) {
    case ReferenceSource::kLaser:
      return "laser";
    case ReferenceSource::kMap:
      return "map";
    case ReferenceSource::kCorners:
      return "corners";
  }
  return "?";
}

bool ReprojectionOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (!(gate_deg > 0 && gate_deg <= 90)) return fail("the gate must lie in (0, 90] degrees");
  if (!(reference.max_scan_gap_s > 0))
    return fail("the largest scan-to-image gap must be positive");
  if (!(reference.max_corner_range > 0)) return fail("the corners' range must be positive");
  return features.IsValid(why);
}

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string span_s(std::int64_t a, std::int64_t b) {
  return std::to_string(a) + " to " + std::to_string(b) + " ns";
}

bool inside_wheel(const dataset::Dataset& d, std::int64_t t) {
  return d.has_wheel() && t >= d.wheel().front().timestamp_ns && t <= d.wheel().back().timestamp_ns;
}

References laser_references(const dataset::Dataset& data, const ReferenceOptions& o) {
  const auto laser = dataset::load_laser(data.root());
  const std::string dir = (fs::path(data.root()) / "laser0").string();
  if (!laser) throw InputError(dir, 0, "no laser0/ folder: the dataset has no laser scans");
  if (!data.has_wheel())
    throw InputError(dir, 0, "the scans need wheel0/ to be moved to the images' times");
  References refs;
  refs.source = ReferenceSource::kLaser;
  const auto& scans = laser->scans;
  const Pose2d sensor(laser->sensor.x, laser->sensor.y, laser->sensor.yaw);
  const auto max_gap = static_cast<std::int64_t>(o.max_scan_gap_s * 1e9);
  for (std::size_t i = 0; i < data.size(); ++i) {
    const std::int64_t t = data.odometry_time(i);
    auto it = std::lower_bound(
        scans.begin(), scans.end(), t, [](const dataset::LaserScan& s, std::int64_t v) {
          return s.timestamp_ns < v;
        });
    if (it == scans.end() ||
        (it != scans.begin() && t - (it - 1)->timestamp_ns < it->timestamp_ns - t))
      it = it == scans.begin() ? it : it - 1;
    const std::int64_t gap = it->timestamp_ns - t;
    if (std::llabs(gap) > max_gap || !inside_wheel(data, t) ||
        !inside_wheel(data, it->timestamp_ns))
      continue;
    // The robot at the scan's time, in its frame at the image's time (odometry, eq. 14).
    const Pose2d scan_pose = compose(odometry_between(data, t, it->timestamp_ns), sensor);
    FrameReference f;
    f.frame = i;
    f.scan_gap_s = static_cast<double>(gap) * 1e-9;
    for (const Eigen::Vector2d& p : scan_points(*it))
      f.points.push_back(transform_point(scan_pose, p));
    std::vector<Eigen::Vector2d> ends;
    for (const Eigen::Vector2d& p : scan_corners(*it, o.corners, &ends))
      f.corners.push_back(transform_point(scan_pose, p));
    for (const Eigen::Vector2d& p : ends) f.ends.push_back(transform_point(scan_pose, p));
    refs.frames.push_back(std::move(f));
  }
  if (refs.frames.empty())
    throw InputError(laser->data_csv,
                     0,
                     "the scans (" + span_s(scans.front().timestamp_ns, scans.back().timestamp_ns) +
                         ") do not overlap the images (" +
                         span_s(data.odometry_time(0), data.odometry_time(data.size() - 1)) +
                         ") inside the wheel data: no image has a scan within " +
                         fmt("%g", o.max_scan_gap_s) + " s");
  std::size_t corners = 0, ends = 0;
  for (const auto& f : refs.frames) corners += f.corners.size(), ends += f.ends.size();
  refs.description = "laser0/: " + laser->describe() + "; " + std::to_string(refs.frames.size()) +
                     " of " + std::to_string(data.size()) + " images have a scan within " +
                     fmt("%g", o.max_scan_gap_s) + " s, " + std::to_string(corners) +
                     " corners (two faces meeting) and " + std::to_string(ends) +
                     " ends (a surface ending in front of a farther one) in all";
  return refs;
}

References map_references(const dataset::Dataset& data) {
  const std::string gt = (fs::path(data.root()) / "ground_truth").string();
  if (!data.ground_truth())
    throw InputError(
        gt,
        0,
        data.ground_truth_error().empty() ? "no ground_truth/ folder" : data.ground_truth_error());
  const auto& g = *data.ground_truth();
  if (!g.has_poses || !g.has_lines)
    throw InputError(gt, 0, "the map check needs poses.csv and lines.csv (a simulated dataset)");
  const auto edges = dataset::load_edges_csv((fs::path(gt) / "edges.csv").string());
  std::map<int, Eigen::Vector2d> where;
  for (const auto& e : edges) where[e.id] = e.p;
  std::map<std::int64_t, Pose2d> pose;
  for (const auto& p : g.poses) pose[p.timestamp_ns] = Pose2d(p.x, p.y, p.theta);
  // The edges the extractor can find: visible over half the annulus (its default threshold,
  // paper Sec. 2); shorter ones (door frames, panels) are often not extracted.
  const CameraGeometry& cam = data.camera();
  const double min_extent = cam.r_min && cam.r_max ? 0.5 * (*cam.r_max - *cam.r_min) : 0.0;
  References refs;
  refs.source = ReferenceSource::kMap;
  std::size_t corners = 0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const auto it = pose.find(data.images()[i].timestamp_ns);
    if (it == pose.end()) continue;
    const Pose2d world_to_robot = inverse(it->second);
    FrameReference f;
    f.frame = i;
    for (const auto& l : g.lines_in_frame(i))
      if (const auto e = where.find(l.line_id);
          e != where.end() && l.r_outer - l.r_inner >= min_extent)
        f.corners.push_back(transform_point(world_to_robot, e->second));
    corners += f.corners.size();
    refs.frames.push_back(std::move(f));
  }
  if (refs.frames.empty())
    throw InputError((fs::path(gt) / "poses.csv").string(), 0, "no pose has an image's timestamp");
  refs.description =
      "ground_truth/: the world's vertical edges visible over half the annulus in each frame, "
      "at the true robot pose, " +
      std::to_string(corners) + " in " + std::to_string(refs.frames.size()) + " frames";
  return refs;
}

References corner_references(const dataset::Dataset& data, const ReferenceOptions& o) {
  const auto corners = dataset::load_corners_csv(o.corners_file);
  if (!data.has_wheel())
    throw InputError(o.corners_file, 0, "the corners need wheel0/ to be carried to each image");
  References refs;
  refs.source = ReferenceSource::kCorners;
  const std::int64_t t0 = data.odometry_time(0);
  if (!inside_wheel(data, t0))
    throw InputError(o.corners_file, 0, "the first image lies outside the wheel data");
  std::size_t n = 0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const std::int64_t t = data.odometry_time(i);
    if (!inside_wheel(data, t)) continue;
    // Dead reckoning from the first image (eq. 14 over every wheel sample).
    const Pose2d to_robot = inverse(odometry_between(data, t0, t));
    FrameReference f;
    f.frame = i;
    for (const auto& c : corners) {
      const Eigen::Vector2d p = transform_point(to_robot, c.p);
      if (p.norm() <= o.max_corner_range) f.corners.push_back(p);
    }
    n += f.corners.size();
    refs.frames.push_back(std::move(f));
  }
  refs.description = o.corners_file + ": " + std::to_string(corners.size()) +
                     " corners in the robot frame of the first image, carried by dead reckoning; " +
                     std::to_string(n) + " corner sightings within " +
                     fmt("%g", o.max_corner_range) + " m";
  return refs;
}

}  // namespace

References load_references(const dataset::Dataset& data, const ReferenceOptions& o) {
  switch (o.source) {
    case ReferenceSource::kLaser:
      return laser_references(data, o);
    case ReferenceSource::kMap:
      return map_references(data);
    case ReferenceSource::kCorners:
      return corner_references(data, o);
  }
  return {};
}

namespace {

const FrameReference* reference_of(const References& refs, std::size_t frame) {
  const auto it = std::lower_bound(
      refs.frames.begin(), refs.frames.end(), frame, [](const FrameReference& f, std::size_t v) {
        return f.frame < v;
      });
  return it != refs.frames.end() && it->frame == frame ? &*it : nullptr;
}

// The frame's image and its lines, extracted by a pipeline of its own (its own centre).
struct Extracted {
  cv::Mat1b image;
  FrameFeatures features;
};

Extracted extract(const dataset::Dataset& data, std::size_t frame, const ReprojectionOptions& o) {
  CameraGeometry g = data.camera();
  if (!o.mask.empty()) g.mask = o.mask;
  FeaturePipeline pipe(g, o.features);
  Extracted e;
  e.image = data.image(frame);
  std::string why;
  if (!pipe.process(e.image, e.features, &why))
    throw InputError(data.images()[frame].path, 0, "no lines extracted: " + why);
  return e;
}

std::vector<double> bearings(const FrameFeatures& f) {
  std::vector<double> b;
  for (const auto& l : f.lines) b.push_back(l.bearing);
  return b;
}

std::string mounting_text(const calib::Extrinsics& x) {
  return "phi " + fmt("%.2f", rad2deg(x.phi)) + " deg, rho " + fmt("%.0f", x.rho * 1e3) +
         " mm, psi " + fmt("%.2f", rad2deg(x.psi)) + " deg";
}

viz::ReprojectionLayer layer_of(const FrameReference* ref,
                                const calib::Extrinsics& x,
                                const std::vector<double>& lines,
                                double gate,
                                const std::string& name,
                                std::size_t frame) {
  viz::ReprojectionLayer layer;
  const Eigen::Vector2d cam = x.position();
  std::vector<double> offsets;
  if (ref) {
    for (const auto& p : ref->points)
      layer.points.emplace_back(camera_bearing(x, p), (p - cam).norm());
    std::vector<double> b;
    for (const auto& p : ref->corners) {
      b.push_back(camera_bearing(x, p));
      layer.corners.emplace_back(b.back(), (p - cam).norm());
    }
    for (const auto& p : ref->ends) {
      b.push_back(camera_bearing(x, p));
      layer.ends.emplace_back(b.back(), (p - cam).norm());
    }
    const std::vector<double> off = match_offsets(b, lines, gate);
    for (std::size_t i = 0; i < off.size(); ++i) {
      const bool ok = !std::isnan(off[i]);
      (i < ref->corners.size() ? layer.matched : layer.ends_matched).push_back(ok);
      if (ok && i < ref->corners.size()) offsets.push_back(std::abs(off[i]));
    }
  }
  layer.title = "frame " + std::to_string(frame) + ", " + name + ": " + mounting_text(x) + "\n";
  if (!ref) {
    layer.title += "no reference";
  } else if (!offsets.empty()) {
    std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
    layer.title += "corners to lines: median " + fmt("%.2f", rad2deg(offsets[offsets.size() / 2])) +
                   " deg, " + std::to_string(offsets.size()) + " of " +
                   std::to_string(layer.corners.size()) + " within " + fmt("%g", rad2deg(gate)) +
                   " deg";
  } else {
    layer.title += std::to_string(layer.corners.size()) + " corners, none within " +
                   fmt("%g", rad2deg(gate)) + " deg of a line";
  }
  return layer;
}

nlohmann::json stats_json(const OffsetStats& s) {
  auto num = [&](double v) { return s.valid() ? nlohmann::json(rad2deg(v)) : nlohmann::json(); };
  return {{"frames", s.frames},
          {"corners", s.corners},
          {"matched", s.matched},
          {"median_abs_offset_deg", num(s.median_abs)},
          {"median_signed_offset_deg", num(s.median_signed)}};
}

nlohmann::json stats_json(const OffsetStats& s,
                          const OffsetStats& ends,
                          const calib::Extrinsics& x) {
  nlohmann::json j = stats_json(s);
  j["mounting"] = {{"phi", x.phi}, {"rho", x.rho}, {"psi", x.psi}};
  j["ends"] = stats_json(ends);
  return j;
}

std::string stats_text(const OffsetStats& s) {
  if (!s.valid()) return "no corner within the gate";
  return fmt("%.3f deg", rad2deg(s.median_abs)) + " (" + std::to_string(s.matched) + " of " +
         std::to_string(s.corners) + " corners matched)";
}

}  // namespace

ReprojectionResult check_reprojection(const dataset::Dataset& data,
                                      const References& refs,
                                      const std::vector<std::vector<double>>& given_lines,
                                      const calib::Extrinsics& before,
                                      const calib::Extrinsics& after,
                                      const ReprojectionOptions& o) {
  ReprojectionResult r;
  r.source = refs.source;
  r.description = refs.description;
  r.gate = deg2rad(o.gate_deg);
  r.before = before;
  r.after = after;
  for (const std::size_t f : o.frames)
    if (f >= data.size())
      throw InputError("frame " + std::to_string(f) + " is not an image of the dataset (0.." +
                       std::to_string(data.size() - 1) + ")");
  r.frames_drawn = o.frames;
  if (r.frames_drawn.empty() && !refs.frames.empty())
    r.frames_drawn.push_back(refs.frames[refs.frames.size() / 2].frame);
  std::vector<std::vector<double>> lines = given_lines;
  if (lines.empty()) {
    // Every frame with a reference, each extracted on its own (the picture's frames too).
    lines.resize(data.size());
    std::size_t done = 0;
    for (const auto& f : refs.frames) {
      if (!data.images()[f.frame].missing)
        lines[f.frame] = bearings(extract(data, f.frame, o).features);
      if (o.progress) o.progress(++done, refs.frames.size());
    }
  }
  r.stats_before = corner_line_offsets(refs, lines, before, r.gate);
  r.stats_after = corner_line_offsets(refs, lines, after, r.gate);
  r.ends_before = corner_line_offsets(refs, lines, before, r.gate, true);
  r.ends_after = corner_line_offsets(refs, lines, after, r.gate, true);
  std::vector<cv::Mat> rows;
  for (const std::size_t f : r.frames_drawn) {
    const Extracted e = extract(data, f, o);
    const std::vector<double> b = bearings(e.features);
    const FrameReference* ref = reference_of(refs, f);
    const int sign = data.camera().bearing_sign;
    rows.push_back(viz::hconcat_pictures(
        {viz::draw_reprojection(
             e.image, e.features.circle, sign, b, layer_of(ref, before, b, r.gate, "before", f)),
         viz::draw_reprojection(
             e.image, e.features.circle, sign, b, layer_of(ref, after, b, r.gate, "after", f))}));
  }
  r.picture = viz::vconcat_pictures(rows);
  return r;
}

std::string ReprojectionResult::message() const {
  std::string m = std::string("check by eye against the ") + to_string(source) +
                  ": corner-to-line bearing offset, median over " +
                  std::to_string(stats_after.frames) + " frames, gate " + fmt("%g", rad2deg(gate)) +
                  " deg: before " + stats_text(stats_before) + ", after " + stats_text(stats_after);
  if (ends_after.corners > 0)
    m += "; the scan's ends (to half a ray): before " + stats_text(ends_before) + ", after " +
         stats_text(ends_after);
  return m;
}

std::string ReprojectionResult::json() const {
  nlohmann::json j;
  j["source"] = to_string(source);
  j["description"] = description;
  j["gate_deg"] = rad2deg(gate);
  j["frames_drawn"] = frames_drawn;
  j["before"] = stats_json(stats_before, ends_before, before);
  j["after"] = stats_json(stats_after, ends_after, after);
  return j.dump();
}

std::string ReprojectionResult::html(const std::string& png) const {
  std::string text;  // the description, HTML-escaped (it may hold a file name)
  for (const char ch : description)
    text += ch == '<' ? "&lt;" : ch == '>' ? "&gt;" : ch == '&' ? "&amp;" : std::string(1, ch);
  std::string h =
      "<h2>Check by eye: reference corners on the image (the paper's Figs. 23 and 26)</h2>\n<p>" +
      text +
      ". Red ticks: the reference's corners, where vertical edges stand (orange: no extracted "
      "line within " +
      fmt("%g", rad2deg(gate)) +
      " deg); cyan: the extracted lines; green: the scan's points (radius grows with "
      "distance).</p>\n<table><tr><th>mounting</th><th>phi [deg]</th><th>rho [mm]</th><th>psi "
      "[deg]</th><th>corners matched</th><th>median |offset| [deg]</th><th>ends matched</th>"
      "<th>median |offset| of ends [deg]</th></tr>\n";
  auto cells = [&](const OffsetStats& s) {
    return "<td>" + std::to_string(s.matched) + " / " + std::to_string(s.corners) + "</td><td>" +
           (s.valid() ? fmt("%.3f", rad2deg(s.median_abs)) : std::string("not determined")) +
           "</td>";
  };
  auto row = [&](const char* name,
                 const calib::Extrinsics& x,
                 const OffsetStats& s,
                 const OffsetStats& e) {
    h += std::string("<tr><td>") + name + "</td><td>" + fmt("%.3f", rad2deg(x.phi)) + "</td><td>" +
         fmt("%.2f", x.rho * 1e3) + "</td><td>" + fmt("%.3f", rad2deg(x.psi)) + "</td>" + cells(s) +
         cells(e) + "</tr>\n";
  };
  row("before (prior)", before, stats_before, ends_before);
  row("after (estimate)", after, stats_after, ends_after);
  h += "</table>\n<img src=\"" + png + "\" alt=\"reference corners drawn on the image with the " +
       "prior mounting (left) and the estimated one (right)\">\n";
  return h;
}

}  // namespace omnivert::pipeline
