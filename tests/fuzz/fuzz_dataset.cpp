// libFuzzer harness of the dataset reader (Dataset::load): a valid three-frame dataset with
// ground truth is laid out once; each input replaces one of its files (OMNIVERT_FUZZ_FILE:
// cam0/sensor.yaml, cam0/data.csv, wheel0/sensor.yaml, wheel0/data.csv or a ground_truth/
// file) and the dataset is loaded and used as the tools use it. Seeds: corpus/<harness>/.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>

#include <opencv2/imgcodecs.hpp>

#include "fuzz_support.hpp"
#include "omnivert/dataset/dataset.hpp"

#ifndef OMNIVERT_FUZZ_FILE
#error "OMNIVERT_FUZZ_FILE names the dataset file the input replaces"
#endif

namespace {

namespace fs = std::filesystem;
using omnivert::fuzz::scratch;
using omnivert::fuzz::write_file;

// The valid dataset around the fuzzed file: 16x12 images, ticks with a wrapping counter.
const std::pair<const char*, const char*> kFiles[] = {
    {"cam0/sensor.yaml", "resolution: [16, 12]\ncenter: [8, 6]\nr_min: 2\nr_max: 5\n"},
    {"cam0/data.csv",
     "#timestamp [ns],filename\n1000000000,a.png\n1100000000,b.png\n"
     "1200000000,a.png\n"},
    {"wheel0/sensor.yaml",
     "wheel_base: 0.5\nunit: ticks\nticks_per_meter_left: 1000\n"
     "ticks_per_meter_right: 1000\ncounter_bits: 16\nodometry_k: 0.01\n"},
    {"wheel0/data.csv",
     "#timestamp [ns],left [ticks],right [ticks]\n900000000,65530,10\n"
     "1150000000,20,60\n1300000000,100,90\n"},
    {"ground_truth/extrinsics.yaml", "phi: 0.1\nrho: 0.2\npsi: -0.3\n"},
    {"ground_truth/poses.csv",
     "#timestamp [ns],x [m],y [m],theta [rad]\n1000000000,0,0,0\n"
     "1200000000,0.1,0,0.05\n"},
    {"ground_truth/lines.csv",
     "#timestamp [ns],frame,line_id,bearing [rad],r_inner [px],"
     "r_outer [px]\n1000000000,0,0,0.5,2,5\n1100000000,1,0,0.6,2,5\n"},
};

const fs::path& dataset_dir() {
  static const fs::path dir = [] {
    const fs::path d = scratch() / "dataset";
    for (const auto& [name, text] : kFiles) write_file(d / name, text);
    fs::create_directories(d / "cam0/data");
    const cv::Mat1b grey(12, 16, std::uint8_t{90});
    const cv::Mat3b colour(12, 16, cv::Vec3b(10, 200, 30));
    if (!cv::imwrite((d / "cam0/data/a.png").string(), grey)) std::abort();
    if (!cv::imwrite((d / "cam0/data/b.png").string(), colour)) std::abort();
    return d;
  }();
  return dir;
}

// What the tools do with a loaded dataset: every image, the odometry at each image, a time
// offset, the ground truth per frame.
void use(omnivert::dataset::Dataset& d) {
  for (std::size_t i = 0; i < d.size(); ++i) {
    omnivert::fuzz::expect_input_error_or_success([&] { (void)d.image(i); });
  }
  if (d.has_wheel()) {
    for (const auto& t : d.travel_at_images()) {
      if (!std::isfinite(t.left) || !std::isfinite(t.right)) std::abort();
    }
    (void)d.set_image_time_offset(0);
  }
  if (const auto& gt = d.ground_truth()) {
    for (std::size_t i = 0; i < d.size(); ++i) {
      for (const auto& l : gt->lines_in_frame(i)) {
        if (!std::isfinite(l.bearing)) std::abort();
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path& dir = dataset_dir();
  write_file(dir / OMNIVERT_FUZZ_FILE, omnivert::fuzz::as_text(data, size));
  omnivert::fuzz::expect_input_error_or_success([&] {
    omnivert::dataset::LoadOptions options;
    options.allow_missing_images = true;
    auto d = omnivert::dataset::Dataset::load(dir.string(), options);
    use(d);
  });
  return 0;
}
