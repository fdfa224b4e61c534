// The built-in worlds (world.hpp): corridor, office, hall. Each is built from a fixed seed so
// that a preset is the same world everywhere.
#include <algorithm>
#include <cmath>
#include <random>

#include "omnivert/core/error.hpp"
#include "omnivert/sim/world.hpp"

namespace omnivert::sim {

namespace {

struct PresetBuilder {
  World& world;
  std::mt19937_64 rng;
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }

  // A grey level at least `min_gap` away from `other`, for edges of varied contrast.
  double contrasting(double other, double min_gap, double max_gap) {
    const double gap = uniform(min_gap, max_gap);
    double v = (pick(2) == 0 ? other - gap : other + gap);
    if (v < 20 || v > 235) v = (v < 20 ? other + gap : other - gap);
    return std::clamp(v, 15.0, 240.0);
  }

  // A door: a frame (low contrast against the wall) around a door leaf (high contrast).
  void door(Wall& w, double s, double width) {
    Panel frame;
    frame.s0 = s - 0.06;
    frame.s1 = s + width + 0.06;
    frame.z0 = 0.0;
    frame.z1 = 2.1;
    frame.intensity = contrasting(w.intensity, 12, 30);
    frame.pattern = Pattern::kFlat;
    w.panels.push_back(frame);
    Panel leaf;
    leaf.s0 = s;
    leaf.s1 = s + width;
    leaf.z0 = 0.0;
    leaf.z1 = 2.04;
    leaf.intensity = contrasting(w.intensity, 35, 90);
    leaf.pattern = pick(2) == 0 ? Pattern::kWave : Pattern::kStripes;
    leaf.period = uniform(0.15, 0.5);
    leaf.angle_deg = uniform(-70, 70);
    leaf.amplitude = uniform(6, 18);
    w.panels.push_back(leaf);
  }

  // A poster or board: partial-height panel with its own pattern.
  void poster(Wall& w, double s, double width, double z0, double z1) {
    Panel p;
    p.s0 = s;
    p.s1 = s + width;
    p.z0 = z0;
    p.z1 = z1;
    p.intensity = contrasting(w.intensity, 25, 100);
    p.pattern = static_cast<Pattern>(pick(3));
    p.period = uniform(0.05, 0.3);
    p.angle_deg = uniform(-80, 80);
    p.amplitude = uniform(10, 35);
    w.panels.push_back(p);
  }

  void skirting(Wall& w) {
    Panel p;
    p.s0 = 0.0;
    p.s1 = w.length();
    p.z0 = 0.0;
    p.z1 = 0.1;
    p.intensity = std::clamp(w.intensity * 0.55, 15.0, 240.0);
    w.panels.push_back(p);
  }

  Wall wall(Eigen::Vector2d a, Eigen::Vector2d b, double intensity, double texture = 9.0) {
    Wall w;
    w.from = a;
    w.to = b;
    w.intensity = intensity;
    w.texture = texture;
    w.texture_scale = uniform(0.03, 0.08);
    return w;
  }
};

World make_corridor() {
  World world;
  world.name = "corridor";
  world.height = 2.6;
  world.seed = 11;
  world.floor = {85, 22, 0.5};
  world.ceiling = {205, 14, 0.6};
  world.start = {0.0, -0.35, 0.0};
  PresetBuilder b{world, std::mt19937_64(2011)};
  const double x0 = -3.0, x1 = 21.0, y0 = -1.1, y1 = 1.1;
  // Long walls in segments of different paint, with doors, posters and pillars.
  for (double side : {-1.0, 1.0}) {
    const double y = side < 0 ? y0 : y1;
    double x = x0;
    while (x < x1 - 1e-9) {
      const double len = std::min(x1 - x, b.uniform(3.0, 5.0));
      Wall w = b.wall({x, y}, {x + len, y}, b.uniform(120, 200));
      if (b.pick(2) == 0) {  // a full-height paint change
        Strip s;
        s.s0 = b.uniform(0.3, len * 0.4);
        s.s1 = s.s0 + b.uniform(0.3, 0.8);
        s.intensity = b.contrasting(w.intensity, 15, 60);
        w.strips.push_back(s);
      }
      double s = b.uniform(0.4, 0.9);
      while (s < len - 1.3) {
        const int what = b.pick(3);
        if (what == 0) {
          b.door(w, s, 0.9);
          s += 0.9 + b.uniform(0.5, 1.2);
        } else if (what == 1) {
          const double width = b.uniform(0.3, 0.9), z0 = b.uniform(0.8, 1.3);
          b.poster(w, s, width, z0, z0 + b.uniform(0.4, 0.9));
          s += width + b.uniform(0.4, 1.0);
        } else {
          s += b.uniform(0.3, 0.8);
        }
      }
      b.skirting(w);
      world.walls.push_back(w);
      x += len;
    }
  }
  // Corridor ends.
  Wall end0 = b.wall({x0, y1}, {x0, y0}, 170);
  b.door(end0, 0.65, 0.9);
  world.walls.push_back(end0);
  Wall end1 = b.wall({x1, y0}, {x1, y1}, 140);
  b.poster(end1, 0.5, 1.2, 0.9, 1.9);
  world.walls.push_back(end1);
  // Pillars built into the walls.
  for (double x : {2.7, 9.1, 15.4}) {
    world.add_box({x, y0 + 0.12}, {0.35, 0.24}, 0.0, world.height, b.uniform(110, 190));
  }
  for (double x : {6.3, 12.6}) {
    world.add_box({x, y1 - 0.12}, {0.35, 0.24}, 0.0, world.height, b.uniform(110, 190));
  }
  return world;
}

World make_office() {
  World world;
  world.name = "office";
  world.height = 2.8;
  world.seed = 23;
  world.floor = {110, 18, 0.6};
  world.ceiling = {215, 10, 0.6};
  world.start = {1.5, 1.4, 0.0};
  PresetBuilder b{world, std::mt19937_64(2023)};
  const Eigen::Vector2d c[4] = {{-1.0, -1.5}, {10.0, -1.5}, {10.0, 5.5}, {-1.0, 5.5}};
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector2d a = c[i], e = c[(i + 1) % 4];
    const double len = (e - a).norm();
    // Each side in two or three differently painted pieces.
    double s = 0.0;
    while (s < len - 1e-9) {
      const double piece = std::min(len - s, b.uniform(2.5, 4.5));
      const Eigen::Vector2d dir = (e - a) / len;
      Wall w = b.wall(a + s * dir, a + (s + piece) * dir, b.uniform(130, 210));
      double t = b.uniform(0.3, 0.8);
      while (t < piece - 1.0) {
        const int what = b.pick(4);
        if (what == 0 && i != 1) {
          b.door(w, t, 0.9);
          t += 0.9 + b.uniform(0.4, 1.0);
        } else if (what == 1 || (what == 0 && i == 1)) {  // window
          Panel win;
          win.s0 = t;
          win.s1 = t + b.uniform(0.8, 1.4);
          win.z0 = 0.9;
          win.z1 = 2.2;
          win.intensity = b.uniform(220, 245);
          win.pattern = Pattern::kStripes;
          win.period = b.uniform(0.2, 0.45);
          win.amplitude = b.uniform(8, 20);
          w.panels.push_back(win);
          t = win.s1 + b.uniform(0.3, 0.9);
        } else if (what == 2) {
          const double width = b.uniform(0.4, 1.0), z0 = b.uniform(0.9, 1.4);
          b.poster(w, t, width, z0, z0 + b.uniform(0.4, 0.8));
          t += width + b.uniform(0.3, 0.9);
        } else {
          t += b.uniform(0.3, 0.7);
        }
      }
      b.skirting(w);
      world.walls.push_back(w);
      s += piece;
    }
  }
  // Pillars.
  world.add_box({4.2, 4.0}, {0.45, 0.45}, 0.0, world.height, 175);
  world.add_box({8.0, 0.2}, {0.45, 0.45}, 0.0, world.height, 150);
  // Furniture: desks, cabinets, shelves (partial-height vertical edges), kept out of the
  // free area x in [0.6, 8.4], y in [0.6, 3.4] around the start.
  world.add_box({1.0, -0.9}, {1.4, 0.7}, 0.0, 0.75, 95);
  world.add_box({3.4, -1.05}, {1.6, 0.6}, 0.0, 0.75, 120);
  world.add_box({6.0, -1.25}, {0.8, 0.4}, 0.0, 1.9, 70);
  world.add_box({9.6, 2.0}, {0.6, 1.2}, 0.0, 1.2, 190, 10);
  world.add_box({2.0, 4.8}, {1.2, 0.6}, 0.1, 0.75, 100);
  world.add_box({6.2, 4.9}, {0.9, 0.45}, 0.0, 1.8, 60);
  world.add_box({-0.6, 2.5}, {0.5, 1.0}, 0.0, 1.1, 140);
  world.add_box({8.9, 4.6}, {0.7, 0.7}, 0.6, 0.9, 200);
  return world;
}

World make_hall() {
  World world;
  world.name = "hall";
  world.height = 4.0;
  world.seed = 37;
  world.floor = {120, 8, 0.4};
  world.ceiling = {220, 6, 1.2};
  world.start = {2.0, 2.0, 0.0};
  PresetBuilder b{world, std::mt19937_64(2037)};
  const double x0 = -2.0, x1 = 14.0, y0 = -2.0, y1 = 6.0;
  // The same window, every 1.5 m, on both long walls: almost identical vertical edges
  // (Sec. 9.1, Fig. 10: repetitive texture causes the false matches).
  // Identical mullioned windows every 1.5 m with an identical radiator below each, and
  // lattices of identical slats: many vertical edges that look alike and lie side by side
  // at nearly the same distance, so their descriptors are nearly the same.
  auto flat_panel = [](Wall& w, double s0, double s1, double z0, double z1, double intensity) {
    Panel p;
    p.s0 = s0;
    p.s1 = s1;
    p.z0 = z0;
    p.z1 = z1;
    p.intensity = intensity;
    w.panels.push_back(p);
  };
  auto windows = [&](Wall& w) {
    for (double s = 0.4; s + 1.2 < w.length() - 0.3; s += 1.5) {
      flat_panel(w, s - 0.06, s + 1.26, 0.9, 3.2, 90);  // frame
      Panel glass;
      glass.s0 = s;
      glass.s1 = s + 1.2;
      glass.z0 = 0.96;
      glass.z1 = 3.14;
      glass.intensity = 235;
      glass.pattern = Pattern::kStripes;
      glass.period = 0.7;
      glass.amplitude = 10;
      w.panels.push_back(glass);
      for (int m = 1; m < 4; ++m) {  // mullions: four panes
        const double c = s + 0.3 * m;
        flat_panel(w, c - 0.025, c + 0.025, 0.96, 3.14, 90);
      }
      for (int f = 0; f < 7; ++f) {  // radiator fins
        const double c = s + 0.24 + 0.12 * f;
        flat_panel(w, c, c + 0.05, 0.15, 0.7, 235);
      }
    }
  };
  auto lattice = [&](Wall& w, double s0, double s1) {
    for (double s = s0; s + 0.1 < s1; s += 0.25)
      flat_panel(w, s, s + 0.1, 0.0, w.z1 < 0 ? 4.0 : w.z1, 95);
  };
  Wall south = b.wall({x0, y0}, {x1, y0}, 175, 2.0);
  windows(south);
  Wall north = b.wall({x1, y1}, {x0, y1}, 175, 2.0);
  windows(north);
  Wall east = b.wall({x1, y0}, {x1, y1}, 160, 2.0);
  lattice(east, 0.5, 3.2);
  b.door(east, 3.5, 1.6);
  lattice(east, 5.4, 7.6);
  Wall west = b.wall({x0, y1}, {x0, y0}, 160, 2.0);
  lattice(west, 0.5, 3.2);
  b.door(west, 3.5, 1.6);
  lattice(west, 5.4, 7.6);
  for (Wall* w : {&south, &north, &east, &west}) {
    b.skirting(*w);
    world.walls.push_back(*w);
  }
  // Two rows of identical pillars.
  for (double x = 0.5; x < x1 - 0.5; x += 3.0) {
    world.add_box({x, -0.6}, {0.4, 0.4}, 0.0, world.height, 200, 2.0);
    world.add_box({x, 4.6}, {0.4, 0.4}, 0.0, world.height, 200, 2.0);
  }
  return world;
}

double world_top(const World& w) { return w.height - 0.1; }

// A wall from a to b in pieces of 1.5-5 m, each its own paint, texture (coarse to fine) and
// features: doors, windows, posters, paint strips, lattices of identical slats.
void random_walls(PresetBuilder& b, const Eigen::Vector2d& a, const Eigen::Vector2d& e) {
  const double len = (e - a).norm();
  const Eigen::Vector2d dir = (e - a) / len;
  for (double s = 0.0; s < len - 1e-9;) {
    const double piece = std::min(len - s, b.uniform(1.5, 5.0));
    Wall w = b.wall(a + s * dir, a + (s + piece) * dir, b.uniform(90, 215), b.uniform(1.0, 14.0));
    w.texture_scale = b.uniform(0.005, 0.1);  // fine to coarse
    for (double t = b.uniform(0.2, 0.8); t < piece - 0.6;) {
      switch (b.pick(7)) {
        case 0:
          if (t + 1.1 > piece) {
            t = piece;
            break;
          }
          b.door(w, t, b.uniform(0.7, 1.0));
          t += 1.1 + b.uniform(0.3, 1.2);
          break;
        case 1: {
          const double width = b.uniform(0.3, std::min(1.2, piece - t)), z0 = b.uniform(0.6, 1.4);
          b.poster(w, t, width, z0, z0 + b.uniform(0.3, 1.0));
          t += width + b.uniform(0.3, 1.0);
          break;
        }
        case 2: {
          Strip st;
          st.s0 = t;
          st.s1 = std::min(piece, t + b.uniform(0.1, 0.8));
          st.intensity = b.contrasting(w.intensity, 10, 70);
          w.strips.push_back(st);
          t = st.s1 + b.uniform(0.3, 1.0);
          break;
        }
        case 3: {  // slats: many edges that look alike, side by side
          const double pitch = b.uniform(0.15, 0.35), width = pitch * b.uniform(0.3, 0.6);
          const double end = std::min(piece - 0.1, t + b.uniform(0.8, 2.5));
          const double grey = b.contrasting(w.intensity, 20, 80);
          for (; t + width < end; t += pitch) {
            Panel p;
            p.s0 = t;
            p.s1 = t + width;
            p.z1 = b.uniform(0.5, 1.0) < 0.75 ? 2.2 : 1.0;
            p.intensity = grey;
            w.panels.push_back(p);
          }
          t += b.uniform(0.3, 0.8);
          break;
        }
        case 4: {  // a window: bright, with a faint pattern
          Panel win;
          win.s0 = t;
          win.s1 = std::min(piece - 0.05, t + b.uniform(0.6, 1.6));
          win.z0 = b.uniform(0.7, 1.1);
          win.z1 = std::min(world_top(b.world), win.z0 + b.uniform(0.8, 1.6));
          win.intensity = b.uniform(215, 248);
          win.pattern = Pattern::kStripes;
          win.period = b.uniform(0.2, 0.6);
          win.amplitude = b.uniform(5, 20);
          w.panels.push_back(win);
          t = win.s1 + b.uniform(0.3, 1.0);
          break;
        }
        default:
          t += b.uniform(0.3, 1.0);
      }
    }
    if (b.pick(3) != 0) b.skirting(w);
    b.world.walls.push_back(w);
    s += piece;
  }
}

}  // namespace

World random_world(std::uint64_t seed, const std::vector<Eigen::Vector2d>& path) {
  World world;
  world.name = "random-" + std::to_string(seed);
  PresetBuilder b{world, std::mt19937_64(seed * 7919 + 101)};
  world.seed = seed + 1000;
  world.height = b.uniform(2.4, 4.5);
  world.floor = {b.uniform(50, 160), b.uniform(5, 30), b.uniform(0.3, 1.2)};
  world.ceiling = {b.uniform(150, 235), b.uniform(4, 18), b.uniform(0.4, 1.4)};
  world.start = Eigen::Vector3d::Zero();
  Eigen::Vector2d lo(0, 0), hi(0, 0);
  for (const Eigen::Vector2d& p : path) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // The room: the path's box and 0.9-3.5 m on each side (a corridor when both sides of an
  // axis are narrow, a hall when they are wide).
  const Eigen::Vector2d r0(lo.x() - b.uniform(0.9, 3.5), lo.y() - b.uniform(0.9, 3.5));
  const Eigen::Vector2d r1(hi.x() + b.uniform(0.9, 3.5), hi.y() + b.uniform(0.9, 3.5));
  const Eigen::Vector2d c[4] = {r0, {r1.x(), r0.y()}, r1, {r0.x(), r1.y()}};
  for (int i = 0; i < 4; ++i) random_walls(b, c[i], c[(i + 1) % 4]);
  // Pillars and furniture between the path (kept 0.6 m clear) and the walls.
  const Eigen::Vector2d f0 = lo.array() - 0.6, f1 = hi.array() + 0.6;
  const int boxes = b.pick(9);
  for (int k = 0, tries = 0; k < boxes && tries < 200; ++tries) {
    const Eigen::Vector2d size(b.uniform(0.25, 1.4), b.uniform(0.25, 1.0));
    const Eigen::Vector2d at(b.uniform(r0.x() + 0.1, r1.x() - 0.1),
                             b.uniform(r0.y() + 0.1, r1.y() - 0.1));
    const double reach = 0.5 * size.norm();
    const bool clear = at.x() + reach < f0.x() || at.x() - reach > f1.x() ||
                       at.y() + reach < f0.y() || at.y() - reach > f1.y();
    const bool inside = at.x() - reach > r0.x() && at.x() + reach < r1.x() &&
                        at.y() - reach > r0.y() && at.y() + reach < r1.y();
    if (!clear || !inside) continue;
    const bool pillar = b.pick(3) == 0;
    world.add_box(at,
                  pillar ? Eigen::Vector2d(0.3, 0.3) : size,
                  b.uniform(-0.5, 0.5),
                  pillar ? world.height : b.uniform(0.5, 2.0),
                  b.uniform(50, 220),
                  b.uniform(2, 12));
    ++k;
  }
  return world;
}

std::vector<std::string> world_presets() { return {"corridor", "office", "hall"}; }

World world_preset(const std::string& name) {
  if (name == "corridor") return make_corridor();
  if (name == "office") return make_office();
  if (name == "hall") return make_hall();
  throw InputError("unknown world '" + name +
                   "' (presets: corridor, office, hall; or a YAML file)");
}

}  // namespace omnivert::sim
