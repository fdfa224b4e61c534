#include "omnivert/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <yaml-cpp/yaml.h>
#include <opencv2/imgproc.hpp>

#include "core/yaml_fields.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::sim {

namespace {

constexpr double kMergeDistance = 1e-3;  // edges closer than 1 mm are one edge

}  // namespace

void World::add_box(const Eigen::Vector2d& center,
                    const Eigen::Vector2d& size,
                    double yaw,
                    double box_height,
                    double intensity,
                    double texture) {
  const Eigen::Vector2d ex(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d ey(-ex.y(), ex.x());
  const Eigen::Vector2d hx = 0.5 * size.x() * ex, hy = 0.5 * size.y() * ey;
  const Eigen::Vector2d c[4] = {
      center - hx - hy, center + hx - hy, center + hx + hy, center - hx + hy};
  // Faces lit differently, so that each corner of the box is an edge of some contrast.
  const double shade[4] = {1.0, 0.82, 0.93, 0.74};
  for (int i = 0; i < 4; ++i) {
    Wall w;
    w.from = c[i];
    w.to = c[(i + 1) % 4];
    w.z0 = 0.0;
    w.z1 = box_height;
    w.intensity = std::clamp(intensity * shade[i], 0.0, 255.0);
    w.texture = texture;
    walls.push_back(w);
  }
}

std::vector<VerticalEdge> World::edges() const {
  std::vector<VerticalEdge> out;
  auto add = [&](const Eigen::Vector2d& p, double z0, double z1) {
    for (auto& e : out) {
      if ((e.p - p).norm() < kMergeDistance) {
        e.z0 = std::min(e.z0, z0);
        e.z1 = std::max(e.z1, z1);
        return;
      }
    }
    VerticalEdge e;
    e.id = static_cast<int>(out.size());
    e.p = p;
    e.z0 = z0;
    e.z1 = z1;
    out.push_back(e);
  };
  for (const Wall& w : walls) {
    const double zt = top(w);
    const double len = w.length();
    const Eigen::Vector2d dir = (w.to - w.from) / len;
    add(w.from, w.z0, zt);
    add(w.to, w.z0, zt);
    for (const Strip& s : w.strips) {
      if (std::abs(s.intensity - w.intensity) < 1.0) continue;
      for (double at : {s.s0, s.s1}) {
        if (at > 0.0 && at < len) add(w.from + at * dir, w.z0, zt);
      }
    }
    for (const Panel& p : w.panels) {
      const double z0 = std::max(p.z0, w.z0), z1 = std::min(p.z1, zt);
      if (z1 <= z0) continue;
      for (double at : {p.s0, p.s1}) {
        if (at > 0.0 && at < len) add(w.from + at * dir, z0, z1);
      }
    }
  }
  return out;
}

std::string World::validate() const {
  if (!(height > 0.0)) return "world height must be positive";
  if (walls.empty()) return "a world needs at least one wall";
  for (std::size_t i = 0; i < walls.size(); ++i) {
    const Wall& w = walls[i];
    const std::string which = "wall " + std::to_string(i + 1);
    if (!(w.length() > 1e-3)) return which + " is shorter than 1 mm";
    if (w.z0 < 0.0 || w.z0 >= top(w)) return which + ": need 0 <= z0 < top";
    for (const Panel& p : w.panels) {
      if (!(p.s1 > p.s0) || !(p.z1 > p.z0)) return which + ": a panel needs s0 < s1 and z0 < z1";
      if (!(p.period > 0.0)) return which + ": a panel period must be positive";
    }
    for (const Strip& s : w.strips) {
      if (!(s.s1 > s.s0)) return which + ": a strip needs s0 < s1";
    }
  }
  if (!(floor.tile > 0.0) || !(ceiling.tile > 0.0)) return "tile sizes must be positive";
  return {};
}

// ---------------------------------------------------------------------------------------
// Texture.

WallTexture::WallTexture(const Wall& wall, double wall_height, std::uint64_t seed) {
  const int cols = static_cast<int>(std::ceil(wall.length() / texel_)) + 2;
  const int rows = static_cast<int>(std::ceil(wall_height / texel_)) + 2;
  raster_ = cv::Mat1f(rows, cols, 0.0f);
  if (wall.texture <= 0.0) return;
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> n01(0.0f, 1.0f);
  cv::Mat1f fine(rows, cols), coarse(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) fine(r, c) = n01(rng);
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) coarse(r, c) = n01(rng);
  }
  const double sigma = std::max(0.5, wall.texture_scale / texel_);
  cv::GaussianBlur(fine, fine, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
  cv::GaussianBlur(coarse, coarse, cv::Size(0, 0), 4 * sigma, 4 * sigma, cv::BORDER_REFLECT);
  // Two octaves of smooth noise, each scaled to unit standard deviation.
  for (cv::Mat1f* m : {&fine, &coarse}) {
    cv::Scalar mean, stddev;
    cv::meanStdDev(*m, mean, stddev);
    const double sd = stddev[0] > 0 ? stddev[0] : 1.0;
    *m = (*m - mean[0]) / sd;
  }
  raster_ = (0.6f * fine + 0.8f * coarse) * static_cast<float>(wall.texture);
}

float WallTexture::noise(double s, double z) const {
  if (raster_.empty()) return 0.0f;
  const double x = std::clamp(s / texel_, 0.0, raster_.cols - 1.001);
  const double y = std::clamp(z / texel_, 0.0, raster_.rows - 1.001);
  const int c = static_cast<int>(x), r = static_cast<int>(y);
  const float fx = static_cast<float>(x - c), fy = static_cast<float>(y - r);
  const float* row0 = raster_[r];
  const float* row1 = raster_[r + 1];
  return (1 - fy) * ((1 - fx) * row0[c] + fx * row0[c + 1]) +
         fy * ((1 - fx) * row1[c] + fx * row1[c + 1]);
}

// --------------------------------------------------------------------------------------
// YAML. The presets are in world_presets.cpp.

namespace {

Pattern parse_pattern(const std::string& s, const std::string& file, int line) {
  if (s == "flat") return Pattern::kFlat;
  if (s == "stripes") return Pattern::kStripes;
  if (s == "wave") return Pattern::kWave;
  throw InputError(file, line, "unknown pattern '" + s + "' (expected flat, stripes or wave)");
}

const char* pattern_name(Pattern p) {
  switch (p) {
    case Pattern::kStripes:
      return "stripes";
    case Pattern::kWave:
      return "wave";
    default:
      return "flat";
  }
}

std::pair<double, double> range_field(const YAML::Node& m,
                                      const std::string& key,
                                      const std::string& file,
                                      std::pair<double, double> fallback,
                                      bool required) {
  const auto v = yaml::optional_numbers(m, key, 2, file);
  if (!v) {
    if (required) {
      throw InputError(file, yaml::line_of(m), "missing required field '" + key + ": [a, b]'");
    }
    return fallback;
  }
  if (!((*v)[1] > (*v)[0])) {
    throw InputError(file, yaml::line_of(m[key]), "field '" + key + "' needs a < b");
  }
  return {(*v)[0], (*v)[1]};
}

Eigen::Vector2d point_field(const YAML::Node& m, const std::string& key, const std::string& file) {
  const auto v = yaml::optional_numbers(m, key, 2, file);
  if (!v) throw InputError(file, yaml::line_of(m), "missing required field '" + key + ": [x, y]'");
  return {(*v)[0], (*v)[1]};
}

void read_plane(const YAML::Node& root, const std::string& key, const std::string& file, Plane& p) {
  const YAML::Node n = root[key];
  if (!n) return;
  if (!n.IsMap()) throw InputError(file, yaml::line_of(n), "field '" + key + "' must be a mapping");
  p.intensity = yaml::optional_number(n, "intensity", file, true).value_or(p.intensity);
  p.contrast = yaml::optional_number(n, "contrast", file, true).value_or(p.contrast);
  p.tile = yaml::optional_number(n, "tile", file, true).value_or(p.tile);
  if (!(p.tile > 0)) throw InputError(file, yaml::line_of(n), "field 'tile' must be positive");
}

World parse_world(const std::string& file) {
  const YAML::Node root = yaml::load_file(file);
  World world;
  world.name = yaml::optional_string(root, "name", file)
                   .value_or(std::filesystem::path(file).stem().string());
  world.height = yaml::optional_number(root, "height", file, true).value_or(world.height);
  if (!(world.height > 0)) {
    throw InputError(file, yaml::line_of(root["height"]), "field 'height' must be positive");
  }
  if (const auto seed = yaml::optional_number(root, "seed", file, true)) {
    world.seed = static_cast<std::uint64_t>(*seed);
  }
  if (const auto st = yaml::optional_numbers(root, "start", 3, file)) {
    world.start = {(*st)[0], (*st)[1], (*st)[2]};
  }
  read_plane(root, "floor", file, world.floor);
  read_plane(root, "ceiling", file, world.ceiling);

  const YAML::Node walls = root["walls"];
  if (walls && !walls.IsSequence()) {
    throw InputError(file, yaml::line_of(walls), "field 'walls' must be a list");
  }
  for (std::size_t i = 0; walls && i < walls.size(); ++i) {
    const YAML::Node n = walls[i];
    const int line = yaml::line_of(n);
    if (!n.IsMap()) throw InputError(file, line, "each wall must be a mapping");
    Wall w;
    w.from = point_field(n, "from", file);
    w.to = point_field(n, "to", file);
    if (!(w.length() > 1e-3)) throw InputError(file, line, "wall is shorter than 1 mm");
    const auto z = range_field(n, "z", file, {0.0, -1.0}, false);
    w.z0 = z.first;
    w.z1 = z.second;
    w.intensity = yaml::optional_number(n, "intensity", file, true).value_or(w.intensity);
    w.texture = yaml::optional_number(n, "texture", file, true).value_or(w.texture);
    w.texture_scale =
        yaml::optional_number(n, "texture_scale", file, true).value_or(w.texture_scale);
    if (!(w.texture_scale > 0)) {
      throw InputError(file, line, "field 'texture_scale' must be positive");
    }
    if (const YAML::Node strips = n["strips"]) {
      if (!strips.IsSequence())
        throw InputError(file, yaml::line_of(strips), "'strips' must be a list");
      for (const YAML::Node& sn : strips) {
        Strip s;
        const auto at = range_field(sn, "at", file, {}, true);
        s.s0 = at.first;
        s.s1 = at.second;
        s.intensity = yaml::required_number(sn, "intensity", file, true);
        w.strips.push_back(s);
      }
    }
    if (const YAML::Node panels = n["panels"]) {
      if (!panels.IsSequence())
        throw InputError(file, yaml::line_of(panels), "'panels' must be a list");
      for (const YAML::Node& pn : panels) {
        Panel p;
        const auto at = range_field(pn, "at", file, {}, true);
        const auto pz = range_field(pn, "z", file, {}, true);
        p.s0 = at.first;
        p.s1 = at.second;
        p.z0 = pz.first;
        p.z1 = pz.second;
        p.intensity = yaml::required_number(pn, "intensity", file, true);
        if (const auto pat = yaml::optional_string(pn, "pattern", file)) {
          p.pattern = parse_pattern(*pat, file, yaml::line_of(pn["pattern"]));
        }
        p.period = yaml::optional_number(pn, "period", file, true).value_or(p.period);
        if (!(p.period > 0))
          throw InputError(file, yaml::line_of(pn), "field 'period' must be positive");
        p.angle_deg = yaml::optional_number(pn, "angle_deg", file).value_or(p.angle_deg);
        p.amplitude = yaml::optional_number(pn, "amplitude", file, true).value_or(p.amplitude);
        w.panels.push_back(p);
      }
    }
    world.walls.push_back(w);
  }
  const YAML::Node boxes = root["boxes"];
  if (boxes && !boxes.IsSequence()) {
    throw InputError(file, yaml::line_of(boxes), "field 'boxes' must be a list");
  }
  for (std::size_t i = 0; boxes && i < boxes.size(); ++i) {
    const YAML::Node n = boxes[i];
    if (!n.IsMap()) throw InputError(file, yaml::line_of(n), "each box must be a mapping");
    const Eigen::Vector2d c = point_field(n, "center", file);
    const Eigen::Vector2d size = point_field(n, "size", file);
    if (!(size.x() > 0 && size.y() > 0)) {
      throw InputError(file, yaml::line_of(n["size"]), "box size must be positive");
    }
    const double yaw = yaml::optional_number(n, "yaw", file).value_or(0.0);
    const double h = yaml::optional_number(n, "height", file, true).value_or(world.height);
    const double in = yaml::optional_number(n, "intensity", file, true).value_or(150);
    const double tex = yaml::optional_number(n, "texture", file, true).value_or(6.0);
    world.add_box(c, size, yaw, h, in, tex);
  }
  const std::string problem = world.validate();
  if (!problem.empty()) throw InputError(file, 0, problem);
  return world;
}

}  // namespace

World load_world(const std::string& name_or_file) {
  for (const auto& p : world_presets()) {
    if (p == name_or_file) return world_preset(p);
  }
  std::error_code ec;
  if (!std::filesystem::exists(name_or_file, ec)) {
    throw InputError(
        name_or_file, 0, "no such world file, and not a preset (corridor, office, hall)");
  }
  return parse_world(name_or_file);
}

void save_world(const World& world, const std::string& path) {
  YAML::Emitter out;
  out.SetDoublePrecision(9);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << world.name;
  out << YAML::Key << "height" << YAML::Value << world.height;
  out << YAML::Key << "seed" << YAML::Value << world.seed;
  out << YAML::Key << "start" << YAML::Value << YAML::Flow << YAML::BeginSeq << world.start.x()
      << world.start.y() << world.start.z() << YAML::EndSeq;
  for (const auto& [key, p] :
       {std::pair{"floor", world.floor}, std::pair{"ceiling", world.ceiling}}) {
    out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "intensity" << YAML::Value << p.intensity;
    out << YAML::Key << "contrast" << YAML::Value << p.contrast;
    out << YAML::Key << "tile" << YAML::Value << p.tile << YAML::EndMap;
  }
  out << YAML::Key << "walls" << YAML::Value << YAML::BeginSeq;
  for (const Wall& w : world.walls) {
    out << YAML::BeginMap;
    out << YAML::Key << "from" << YAML::Value << YAML::Flow << YAML::BeginSeq << w.from.x()
        << w.from.y() << YAML::EndSeq;
    out << YAML::Key << "to" << YAML::Value << YAML::Flow << YAML::BeginSeq << w.to.x() << w.to.y()
        << YAML::EndSeq;
    if (w.z1 >= 0 || w.z0 > 0) {
      out << YAML::Key << "z" << YAML::Value << YAML::Flow << YAML::BeginSeq << w.z0 << world.top(w)
          << YAML::EndSeq;
    }
    out << YAML::Key << "intensity" << YAML::Value << w.intensity;
    out << YAML::Key << "texture" << YAML::Value << w.texture;
    out << YAML::Key << "texture_scale" << YAML::Value << w.texture_scale;
    if (!w.strips.empty()) {
      out << YAML::Key << "strips" << YAML::Value << YAML::BeginSeq;
      for (const Strip& s : w.strips) {
        out << YAML::Flow << YAML::BeginMap << YAML::Key << "at" << YAML::Value << YAML::Flow
            << YAML::BeginSeq << s.s0 << s.s1 << YAML::EndSeq << YAML::Key << "intensity"
            << YAML::Value << s.intensity << YAML::EndMap;
      }
      out << YAML::EndSeq;
    }
    if (!w.panels.empty()) {
      out << YAML::Key << "panels" << YAML::Value << YAML::BeginSeq;
      for (const Panel& p : w.panels) {
        out << YAML::Flow << YAML::BeginMap;
        out << YAML::Key << "at" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.s0 << p.s1
            << YAML::EndSeq;
        out << YAML::Key << "z" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.z0 << p.z1
            << YAML::EndSeq;
        out << YAML::Key << "intensity" << YAML::Value << p.intensity;
        out << YAML::Key << "pattern" << YAML::Value << pattern_name(p.pattern);
        if (p.pattern != Pattern::kFlat) {
          out << YAML::Key << "period" << YAML::Value << p.period;
          out << YAML::Key << "angle_deg" << YAML::Value << p.angle_deg;
          out << YAML::Key << "amplitude" << YAML::Value << p.amplitude;
        }
        out << YAML::EndMap;
      }
      out << YAML::EndSeq;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  std::ofstream f(path);
  f << "# omnivert simulator world (format: docs/simulator.md)\n" << out.c_str() << "\n";
  f.close();  // flushed: a full disk shows here
  if (!f) throw InputError(path, 0, "cannot write (disk full, or a folder that is not writable?)");
}

}  // namespace omnivert::sim
