// omnivert study real-images DIR: every image under DIR (recursively) through the pipeline
// at the given options, rotated about its mirror centre and re-lit; lines per image and the
// repeatability of the strongest lines and their descriptors (eval/real_image_study.hpp,
// docs/validation.md#real-images). Writes real_images.txt and real_images.csv in --out.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"
#include "omnivert/eval/real_image_study.hpp"
#include "omnivert/image/image_io.hpp"
#include "pipeline_options.hpp"

namespace omnivert::cli {

namespace {

namespace fs = std::filesystem;

struct RealImagesArgs {
  std::string dir, out;
  std::vector<std::string> sensors;  // SUBFOLDER=FILE
  eval::RealImageStudyOptions study;
};

bool is_image(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e == ".jpg" || e == ".jpeg" || e == ".png" || e == ".bmp" || e == ".tif" || e == ".tiff";
}

void run_real_images(const RealImagesArgs& a) {
  std::string why;
  if (!a.study.IsValid(&why)) throw InputError("invalid options: " + why);
  if (!fs::is_directory(a.dir)) throw InputError(a.dir, 0, "not a folder");
  // Sub-folder (relative to DIR) -> camera geometry of its images.
  std::map<std::string, CameraGeometry> sensors;
  for (const std::string& s : a.sensors) {
    const auto eq = s.find('=');
    if (eq == std::string::npos)
      throw InputError("--sensor " + s + ": expected SUBFOLDER=FILE (a sensor.yaml)");
    sensors[fs::path(s.substr(0, eq)).lexically_normal().string()] =
        load_camera_geometry(s.substr(eq + 1));
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(a.dir))
    if (e.is_regular_file() && is_image(e.path())) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(a.dir, 0, "no images (.jpg, .png, .bmp, .tif) in the folder");
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (!fs::is_directory(a.out)) throw InputError(a.out, 0, "cannot create the output folder");
  std::vector<eval::RealImageResult> results;
  for (const fs::path& f : files) {
    const std::string rel = f.lexically_relative(a.dir).string();
    CameraGeometry g;
    const auto it = sensors.find(fs::path(rel).parent_path().lexically_normal().string());
    if (it != sensors.end()) g = it->second;
    std::fprintf(stderr, "%s\n", rel.c_str());
    results.push_back(eval::study_real_image(rel, read_image(f.string()), g, a.study));
  }
  const std::string table = eval::real_image_table(results);
  write_text_atomic((fs::path(a.out) / "real_images.txt").string(), table);
  write_text_atomic((fs::path(a.out) / "real_images.csv").string(), eval::real_image_csv(results));
  std::printf("%s", table.c_str());
  std::printf("wrote %s/real_images.txt, real_images.csv\n", a.out.c_str());
}

}  // namespace

void add_real_images_study(CLI::App* study) {
  auto a = std::make_shared<RealImagesArgs>();
  CLI::App* cmd = study->add_subcommand(
      "real-images",
      "Real images: lines per image, rotation and lighting repeatability of the strongest lines "
      "and of their descriptors");
  cmd->add_option("DIR", a->dir, "Folder of catadioptric images (searched recursively)")
      ->required();
  cmd->add_option("--out", a->out, "Output folder (created)")->required();
  cmd->add_option("--sensor",
                  a->sensors,
                  "SUBFOLDER=FILE: the images of DIR/SUBFOLDER use this sensor.yaml (centre, "
                  "r_min, r_max); repeatable. Others: centre and annulus detected")
      ->take_all();
  cmd->add_option("--strongest",
                  a->study.strongest,
                  "Lines of each image looked for in its copies, the most significant")
      ->check(kPositive)
      ->capture_default_str();
  cmd->add_option("--tolerance",
                  a->study.tolerance_deg,
                  "A line is found again within this many degrees of its shifted image angle")
      ->check(CLI::Range(0.01, 10.0))
      ->capture_default_str();
  cmd->add_option("--rotations", a->study.rotations_deg, "Rotations about the centre [deg]")
      ->capture_default_str();
  add_pipeline_options(cmd, a->study.pipeline);
  cmd->callback([a] { run_real_images(*a); });
}

}  // namespace omnivert::cli
