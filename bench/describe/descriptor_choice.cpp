// The study behind the descriptor defaults (docs/theory/descriptor.md): both readings of the
// Gaussian window (vote weight / image blur) and both normalisation units (pair / half), measured
// by nearest-neighbour matching of lines between an image and its rotated or re-lit copy.
//
// Usage: descriptor_choice [REAL_IMAGE_DIR]
// Prints one table row per configuration and transform family.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/eval/invariance.hpp"
#include "omnivert/sim/radial_pattern.hpp"

using namespace omnivert;

namespace {

struct Input {
  std::string name;
  cv::Mat gray;
  CameraGeometry geometry;
  bool real;
  sim::RadialPatternOptions pattern;  // for drawn inputs: redraw rotated / with new noise
};

struct Acc {
  int pairs = 0, nn_correct = 0;
  std::vector<double> dist, ratio;
  void add(const eval::LinePairing& p) {
    ++pairs;
    nn_correct += p.nearest_is_correct;
    dist.push_back(p.descriptor_distance);
    ratio.push_back(p.descriptor_distance / p.nearest_wrong_distance);
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()))];
}

// The drawn patterns (seeds 501-508) and, when a folder is given, the real images in it.
std::vector<Input> load_inputs(int argc, char** argv) {
  std::vector<Input> inputs;
  for (int seed = 1; seed <= 8; ++seed) {
    sim::RadialPatternOptions o;
    o.seed = 500 + seed;
    const auto p = sim::draw_radial_pattern(o);
    CameraGeometry g;
    g.width = o.width, g.height = o.height, g.r_min = o.r_min, g.r_max = o.r_max;
    inputs.push_back({"pattern" + std::to_string(seed), p.image, g, false, o});
  }
  const std::string real_dir = argc > 1 ? argv[1] : "";
  for (const char* f : {"VMRImage0.jpg", "imgMei_001.jpg", "KaidanOmni1.jpg"}) {
    const auto path = std::filesystem::path(real_dir) / f;
    if (real_dir.empty() || !std::filesystem::exists(path)) continue;
    inputs.push_back(
        {f, cv::imread(path.string(), cv::IMREAD_GRAYSCALE), CameraGeometry{}, true, {}});
  }

  return inputs;
}

struct Config {
  const char* name;
  DescriptorSmoothing s;
  DescriptorNormalization n;
  bool log;
  double offset = 1.0;
};
constexpr Config kConfigs[] = {
    {"log1/blur/pair",
     DescriptorSmoothing::kGaussianBlur,
     DescriptorNormalization::kPerPair,
     true,
     1.0},
    {"log2/blur/pair",
     DescriptorSmoothing::kGaussianBlur,
     DescriptorNormalization::kPerPair,
     true,
     2.0},
    {"log4/blur/pair",
     DescriptorSmoothing::kGaussianBlur,
     DescriptorNormalization::kPerPair,
     true,
     4.0},
    {"log8/blur/pair",
     DescriptorSmoothing::kGaussianBlur,
     DescriptorNormalization::kPerPair,
     true,
     8.0},
    {"log16/blur/pair",
     DescriptorSmoothing::kGaussianBlur,
     DescriptorNormalization::kPerPair,
     true,
     16.0},
    {"log32/blur/pair",
     DescriptorSmoothing::kGaussianBlur,
     DescriptorNormalization::kPerPair,
     true,
     32.0},
    {"log/blur/half", DescriptorSmoothing::kGaussianBlur, DescriptorNormalization::kPerHalf, true},
    {"blur/pair", DescriptorSmoothing::kGaussianBlur, DescriptorNormalization::kPerPair, false},
    {"blur/half", DescriptorSmoothing::kGaussianBlur, DescriptorNormalization::kPerHalf, false},
    {"weight/pair", DescriptorSmoothing::kGaussianWeight, DescriptorNormalization::kPerPair, false},
    {"weight/half",
     DescriptorSmoothing::kGaussianWeight,
     DescriptorNormalization::kPerHalf,
     false}};
constexpr double kRotations[] = {17, 43, 71, 137, 251};
constexpr double kGains[] = {0.6, 0.8, 1.25, 1.5};  // 1.25 and 1.5 saturate bright regions
constexpr double kGammas[] = {0.7, 0.85, 1.2, 1.4};

// One input under one configuration: its lines found again after each rotation, gain, gamma
// and noise draw, accumulated in acc (rotation, gain, gamma, noise).
void measure(const Input& in, const Config& c, Acc acc[4]) {
  FeaturePipelineOptions po;
  po.descriptor.smoothing = c.s;
  po.descriptor.normalization = c.n;
  po.descriptor.log_intensity = c.log;
  po.descriptor.log_offset = c.offset;
  if (in.real) po.lines.threshold = LineThreshold::kTopK, po.lines.top_k = 25;
  FeaturePipeline probe(in.geometry, po);
  FrameFeatures f0;
  if (!probe.process(in.gray, f0)) return;
  const cv::Mat& gray = in.gray;
  // The annulus as a user's sensor.yaml would give it, for every transformed copy.
  CameraGeometry geo = in.geometry;
  if (in.real) geo.center = f0.circle.center;
  geo.r_min = f0.circle.r_min;
  // Real images: the annulus ends where a rotation brings no new content into a descriptor.
  geo.r_max = in.real ? std::min(f0.circle.r_max,
                                 eval::rotation_safe_r_max(
                                     f0.circle.center, gray.cols, gray.rows, f0.circle.r_min))
                      : f0.circle.r_max;
  FeaturePipeline base(geo, po);
  if (!base.process(gray, f0)) return;
  auto run = [&](const cv::Mat& img, double shift, Acc& a) {
    FeaturePipeline p(geo, po);
    FrameFeatures f;
    if (!p.process(img, f)) return;
    for (const auto& pr : eval::pair_lines(f0, f, shift, deg2rad(0.3))) a.add(pr);
  };
  for (double r : kRotations) {
    if (in.real) {
      run(eval::rotate_about(gray, f0.circle.center, deg2rad(r)), deg2rad(r), acc[0]);
    } else {
      auto o = in.pattern;
      o.rotation_rad = deg2rad(r);
      o.noise_seed = 1000 + static_cast<int>(r);
      run(sim::draw_radial_pattern(o).image, deg2rad(r), acc[0]);
    }
  }
  if (!in.real) {
    for (int k = 0; k < 3; ++k) {
      auto o = in.pattern;
      o.noise_seed = 2000 + k;
      run(sim::draw_radial_pattern(o).image, 0.0, acc[3]);
    }
  }
  for (double g : kGains) run(eval::relight(gray, g, 1.0), 0.0, acc[1]);
  for (double g : kGammas) run(eval::relight(gray, 1.0, g), 0.0, acc[2]);
}

void print_rows(const Config& c, int real, const Acc acc[4]) {
  const char* fam[] = {"rotation", "gain", "gamma", "noise"};
  for (int k = 0; k < 4; ++k) {
    const Acc& a = acc[k];
    if (!a.pairs) continue;
    std::printf("%-12s %-6s %-9s %6d %7.1f %9.3f %9.3f %9.3f %9.3f %9.3f\n",
                c.name,
                real ? "real" : "drawn",
                fam[k],
                a.pairs,
                100.0 * a.nn_correct / a.pairs,
                median(a.dist),
                pct(a.dist, 0.9),
                pct(a.dist, 1.0),
                median(a.ratio),
                pct(a.ratio, 0.9));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<Input> inputs = load_inputs(argc, argv);
  std::printf("%-12s %-6s %-9s %6s %7s %9s %9s %9s %9s %9s\n",
              "config",
              "data",
              "transform",
              "pairs",
              "NN[%]",
              "med.dist",
              "p90.dist",
              "max.dist",
              "med.ratio",
              "p90.ratio");
  for (const Config& c : kConfigs) {
    for (int real = 0; real <= 1; ++real) {
      Acc acc[4];  // rotation, gain, gamma, noise
      for (const Input& in : inputs)
        if (in.real == static_cast<bool>(real)) measure(in, c, acc);
      print_rows(c, real, acc);
    }
  }
  return 0;
}
