// omnivert pattern --out DIR: draws the built-in example image (radial edges at known angles)
// with its sensor.yaml and ground truth, for the quick start and for trying options.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace omnivert::cli {

void add_pattern_command(CLI::App& app) {
  auto o = std::make_shared<sim::RadialPatternOptions>();
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "pattern", "Draw a test image with radial edges at known angles (+ sensor.yaml, truth.csv)");
  cmd->add_option("--out", *out, "Output folder")->required();
  cmd->add_option("--seed", o->seed, "Random seed")->capture_default_str();
  cmd->add_option("--noise", o->noise_sigma, "Gaussian noise, grey levels")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->callback([o, out] {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(*out, ec);
    if (ec) throw InputError(*out, 0, "cannot create the folder: " + ec.message());
    const auto p = sim::draw_radial_pattern(*o);
    write_image_atomic((fs::path(*out) / "pattern.png").string(), p.image);
    std::ostringstream y;
    y << "# Drawn by omnivert pattern (seed " << o->seed << ")\nresolution: [" << o->width << ", "
      << o->height << "]\nr_min: " << o->r_min << "\nr_max: " << o->r_max << "\nbearing_sign: 1\n";
    write_text_atomic((fs::path(*out) / "sensor.yaml").string(), y.str());
    std::ostringstream t;
    t.precision(9);
    t << "# true centre " << p.circle.center.x() << " " << p.circle.center.y() << "\n";
    t << "image_angle_deg,r_from,r_to,full\n";
    for (const auto& e : p.edges)
      t << rad2deg(e.image_angle) << "," << e.r_from << "," << e.r_to << "," << (e.full ? 1 : 0)
        << "\n";
    write_text_atomic((fs::path(*out) / "truth.csv").string(), t.str());
    std::printf("wrote %s/pattern.png, sensor.yaml, truth.csv (%zu edges, centre %.2f %.2f)\n",
                out->c_str(),
                p.edges.size(),
                p.circle.center.x(),
                p.circle.center.y());
  });
}

}  // namespace omnivert::cli
