// The YAML examples of docs/simulator.md are valid input: the first ```yaml block is a world,
// the second a trajectory, and a short simulation with both runs.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "omnivert/sim/simulator.hpp"

namespace omnivert::sim {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> yaml_blocks(const std::string& markdown) {
  std::vector<std::string> out;
  std::istringstream in(markdown);
  std::string line, block;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside && line == "```yaml") {
      inside = true;
      block.clear();
    } else if (inside && line == "```") {
      inside = false;
      out.push_back(block);
    } else if (inside) {
      block += line + "\n";
    }
  }
  return out;
}

TEST(DocsExamples, WorldAndTrajectoryExamplesLoadAndSimulate) {
  std::ifstream in(std::string(OMNIVERT_DOCS_DIR) + "/simulator.md");
  ASSERT_TRUE(in) << "docs/simulator.md not found";
  std::stringstream ss;
  ss << in.rdbuf();
  const auto blocks = yaml_blocks(ss.str());
  ASSERT_GE(blocks.size(), 2u);
  const fs::path dir = fs::temp_directory_path() / ("omnivert_docs_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << blocks[0];
  std::ofstream(dir / "trajectory.yaml") << blocks[1];
  const World w = load_world((dir / "world.yaml").string());
  EXPECT_EQ(w.name, "my_lab");
  EXPECT_EQ(w.walls.size(), 5u);  // one wall and a box
  const Trajectory t = load_trajectory((dir / "trajectory.yaml").string());
  EXPECT_EQ(t.segments.size(), 8u);  // four segments, repeated twice
  SimConfig cfg;
  cfg.max_frames = 2;
  const SimSummary s = simulate(w, t, cfg, (dir / "out").string());
  EXPECT_EQ(s.frames, 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace omnivert::sim
