// Rendering speed at 640x480 on one core (target: >= 20 frames per second).
// Peers measured in the same run: the plain reference renderer (per-pixel ray casting
// against every wall, 4 rays per pixel) and OpenCV's cv::remap of a 640x480 panorama, the
// usual cost of unwarping one omnidirectional frame. items_per_second = frames per second.

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "omnivert/sim/renderer.hpp"
#include "omnivert/sim/sensors.hpp"
#include "omnivert/sim/simulator.hpp"

namespace {

using namespace omnivert::sim;

const char* kWorlds[] = {"corridor", "office", "hall"};

void BM_Render640x480(benchmark::State& state) {
  const World w = world_preset(kWorlds[state.range(0)]);
  const CatadioptricCamera cam;  // 640x480
  const Renderer r(cam, w);
  const Trajectory t = load_trajectory("paper");
  const auto motion = t.pieces(w.start);
  cv::Mat1f img;
  int k = 0;
  for (auto _ : state) {
    const CameraPose pose = camera_pose(pose_at(motion, 0.33 * (k++ % 90)), Extrinsics{}, 0.9);
    r.render(pose, img);
    benchmark::DoNotOptimize(img.data);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(kWorlds[state.range(0)]);
}
BENCHMARK(BM_Render640x480)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

void BM_RenderAndSensor640x480(benchmark::State& state) {
  const World w = world_preset("corridor");
  const CatadioptricCamera cam;
  const Renderer r(cam, w);
  const CameraPose pose = camera_pose(Pose2(w.start), Extrinsics{}, 0.9);
  ImageSensor sensor;
  sensor.blur_sigma = 0.5;
  std::mt19937_64 rng(1);
  cv::Mat1f img;
  cv::Mat1b out;
  for (auto _ : state) {
    r.render(pose, img);
    apply_image_sensor(img, sensor, rng, out);
    benchmark::DoNotOptimize(out.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderAndSensor640x480)->Unit(benchmark::kMillisecond);

void BM_ReferenceRender640x480(benchmark::State& state) {
  const World w = world_preset("corridor");
  const CatadioptricCamera cam;
  const Renderer r(cam, w);
  const CameraPose pose = camera_pose(Pose2(w.start), Extrinsics{}, 0.9);
  cv::Mat1f img;
  for (auto _ : state) {
    r.render_reference(pose, 4, img);
    benchmark::DoNotOptimize(img.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ReferenceRender640x480)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_OpenCvRemap640x480(benchmark::State& state) {
  cv::Mat1b src(480, 640);
  cv::randu(src, 0, 255);
  cv::Mat1f mapx(480, 640), mapy(480, 640);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const double a = u * (2 * CV_PI / 640), r = 60 + v * (155.0 / 480);
      mapx(v, u) = static_cast<float>(321.37 + r * std::cos(a));
      mapy(v, u) = static_cast<float>(238.81 + r * std::sin(a));
    }
  }
  cv::Mat1b dst;
  for (auto _ : state) {
    cv::remap(src, dst, mapx, mapy, cv::INTER_LINEAR);
    benchmark::DoNotOptimize(dst.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_OpenCvRemap640x480)->Unit(benchmark::kMillisecond);

}  // namespace
