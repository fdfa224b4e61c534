#pragma once
// Shared by the pipeline tests: datasets rendered by the simulator into a temporary folder
// (once per test suite, removed with it), copies of them to damage, and checks of a run's
// output folder.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "omnivert/sim/simulator.hpp"

namespace omnivert::testing {

namespace fs = std::filesystem;

// One simulated dataset: `omnivert simulate --world WORLD --trajectory TRAJECTORY --seed SEED
// [--frames FRAMES]`.
struct SimulatedRun {
  std::string world, trajectory;
  std::uint64_t seed = 1;
  int frames = 0;  // 0: the whole trajectory
  // The camera mount (--phi, --rho, --psi); empty: the simulator's default.
  std::optional<sim::Extrinsics> extrinsics = std::nullopt;
};

inline void simulate_into(const SimulatedRun& run, const fs::path& dir) {
  sim::SimConfig cfg;
  cfg.seed = run.seed;
  cfg.max_frames = run.frames;
  if (run.extrinsics) cfg.extrinsics = *run.extrinsics;
  sim::simulate(
      sim::load_world(run.world), sim::load_trajectory(run.trajectory), cfg, dir.string(), true);
}

inline std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  EXPECT_TRUE(in.good()) << file << " cannot be read";
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  ASSERT_TRUE(out.good()) << file << " cannot be written";
}

// The lines of a text file (without their line ends), and back.
inline std::vector<std::string> read_lines(const fs::path& file) {
  std::istringstream in(read_text(file));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

inline void write_lines(const fs::path& file, const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  write_text(file, text);
}

// A copy of a dataset's cam0/, wheel0/ and ground_truth/ at `to` (replaced when present).
inline void copy_dataset(const fs::path& from, const fs::path& to) {
  fs::remove_all(to);
  fs::create_directories(to);
  for (const char* part : {"cam0", "wheel0", "ground_truth"})
    fs::copy(from / part, to / part, fs::copy_options::recursive);
}

// The image file names of cam0/data.csv, in order.
inline std::vector<std::string> image_names(const fs::path& dataset) {
  std::vector<std::string> names;
  for (const std::string& row : read_lines(dataset / "cam0/data.csv")) {
    if (row.empty() || row[0] == '#') continue;
    names.push_back(row.substr(row.find(',') + 1));
  }
  return names;
}

// A uniform grey 640x480 image (lens cap, dark corridor): valid, without lines. Written as a
// PGM under the listed name (images are read by content).
inline void write_grey_frame(const fs::path& file) {
  write_text(file, "P5\n640 480\n255\n" + std::string(640 * 480, static_cast<char>(128)));
}

inline nlohmann::json read_json(const fs::path& file) {
  return nlohmann::json::parse(read_text(file));
}

// The files a calibration run writes (extrinsics.yaml and the robot formats only when it
// determines the extrinsics, or is forced).
inline const std::vector<std::string>& calibration_outputs() {
  static const std::vector<std::string> files{"extrinsics.yaml",
                                              "summary.json",
                                              "report.html",
                                              "states.csv",
                                              "convergence.png",
                                              "tracks.csv",
                                              "tracks.png",
                                              "camera_joint.urdf",
                                              "static_transform_publisher.sh",
                                              "extrinsics_kalibr.yaml"};
  return files;
}

// A run's output folder: every output but extrinsics.yaml and the robot formats present
// (those two together or neither), nothing else (no
// temporary file), no NaN in any text output, summary.json valid JSON.
inline void expect_complete_outputs_without_nan(const fs::path& out) {
  const std::set<std::string> known(calibration_outputs().begin(), calibration_outputs().end());
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_TRUE(known.count(entry.path().filename().string()))
        << "unexpected file in " << out << ": " << entry.path().filename();
  for (const std::string& f : calibration_outputs()) {
    if (f == "extrinsics.yaml" || f == "camera_joint.urdf" ||
        f == "static_transform_publisher.sh" || f == "extrinsics_kalibr.yaml") {
      EXPECT_EQ(fs::exists(out / f), fs::exists(out / "extrinsics.yaml"))
          << f << " and extrinsics.yaml: one without the other in " << out;
    } else {
      EXPECT_TRUE(fs::exists(out / f)) << "no " << f << " in " << out;
    }
  }
  const std::regex nan("[Nn]a[Nn]([^a-zA-Z]|$)");
  for (const char* f : {"extrinsics.yaml",
                        "summary.json",
                        "states.csv",
                        "report.html",
                        "tracks.csv",
                        "camera_joint.urdf",
                        "static_transform_publisher.sh",
                        "extrinsics_kalibr.yaml"}) {
    if (fs::exists(out / f)) {
      EXPECT_FALSE(std::regex_search(read_text(out / f), nan)) << f << " contains a NaN";
    }
  }
  EXPECT_NO_THROW(read_json(out / "summary.json")) << "summary.json does not parse";
}

// Whether a line of `lines` matches the (ECMAScript) regular expression `re`.
inline bool any_matches(const std::vector<std::string>& lines, const std::string& re) {
  const std::regex r(re);
  for (const std::string& l : lines)
    if (std::regex_search(l, r)) return true;
  return false;
}

inline std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s;
}

// A test suite's temporary folder (under the system's, unique to the process) and the
// datasets simulated into it on first use. Derive a suite's fixture from it.
class SimulatedDatasets : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("omnivert_pipeline_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    datasets_.clear();
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(root_, ec);
    datasets_.clear();
  }
  // The simulated dataset `name` of `run`, rendered once in the suite.
  static fs::path dataset(const std::string& name, const SimulatedRun& run) {
    const fs::path dir = root_ / "datasets" / name;
    if (!datasets_.count(name)) {
      simulate_into(run, dir);
      datasets_.insert(name);
    }
    return dir;
  }
  // A path `name` in the suite's work folder, with nothing there yet.
  static fs::path scratch(const std::string& name) {
    const fs::path dir = root_ / "work" / name;
    fs::remove_all(dir);
    fs::create_directories(dir.parent_path());
    return dir;
  }

 private:
  inline static fs::path root_;
  inline static std::set<std::string> datasets_;
};

}  // namespace omnivert::testing
