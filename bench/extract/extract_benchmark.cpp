// Per-frame cost of the front end on a 640x480 frame: mirror centre + radial lines +
// 192-D descriptors (the pipeline of Sec. 2-3), and its stages, against two peers measured
// in the same run on the same frame: ORB (1,000 features, detect + describe) and OpenCV's
// LSD/EDLines + LBD (BinaryDescriptor: detect + compute).
//
// The *_Masked variants run the same stages with an image mask (four struts 8 px wide across
// the annulus and a 60-degree sector near the centre: 9% of the annulus; docs/extraction.md).
//
// Report: median real time per frame (run with --benchmark_repetitions=9
// --benchmark_report_aggregates_only=true).

#include <cstdlib>

#include <benchmark/benchmark.h>
#include <opencv2/features2d.hpp>
#include <opencv2/line_descriptor.hpp>

#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/sim/radial_pattern.hpp"

namespace {

using namespace omnivert;

const sim::RadialPattern& frame() {
  static const sim::RadialPattern p = [] {
    sim::RadialPatternOptions o;
    o.seed = 11;
    o.full_edges = 20;
    o.patches = 8;
    return sim::draw_radial_pattern(o);
  }();
  return p;
}

CameraGeometry geometry() {
  CameraGeometry g;
  g.width = 640;
  g.height = 480;
  g.r_min = 40;
  g.r_max = 220;
  return g;
}

// Four struts and a sector of the robot's reflection masked.
const cv::Mat& mask() {
  static const cv::Mat m = [] {
    cv::Mat u(frame().image.size(), CV_8U, cv::Scalar(255));
    const cv::Point2d c(frame().circle.center.x(), frame().circle.center.y());
    for (double deg : {10.0, 100.0, 190.0, 280.0}) {
      const double a = deg2rad(deg);
      cv::line(u,
               c + 30 * cv::Point2d(std::cos(a), std::sin(a)),
               c + 240 * cv::Point2d(std::cos(a), std::sin(a)),
               cv::Scalar(0),
               8);
    }
    cv::ellipse(u, c, cv::Size(90, 90), 0, 200, 260, cv::Scalar(0), cv::FILLED);
    return u;
  }();
  return m;
}

// The whole front end in steady state: the centre is tracked on every frame (Sec. 2).
// The steady state of a pipeline on the benchmark frame; the first frame estimates the rim.
void run_front_end(benchmark::State& state, FeaturePipeline& pipe) {
  FrameFeatures f;
  pipe.process(frame().image, f);
  for (auto _ : state) {
    pipe.process(frame().image, f);
    benchmark::DoNotOptimize(f.descriptors.data());
  }
  state.counters["lines"] = static_cast<double>(f.lines.size());
}

void BM_FrontEnd(benchmark::State& state) {
  FeaturePipeline pipe(geometry());
  run_front_end(state, pipe);
}
BENCHMARK(BM_FrontEnd)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same with every stage's plain reference path (the centre searched on every frame, the
// edge pass pixel by pixel, the descriptor's per-sample arithmetic): what the fast paths gain,
// measured in the same run. Same lines and descriptors.
void BM_FrontEnd_Reference(benchmark::State& state) {
  FeaturePipelineOptions o;
  o.center.track_px = 0;
  o.center.reference = true;
  o.lines.reference = true;
  o.descriptor.reference = true;
  FeaturePipeline pipe(geometry(), o);
  run_front_end(state, pipe);
}
BENCHMARK(BM_FrontEnd_Reference)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FrontEnd_Masked(benchmark::State& state) {
  FeaturePipeline pipe(geometry());
  pipe.set_mask(mask());
  run_front_end(state, pipe);
}
BENCHMARK(BM_FrontEnd_Masked)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MirrorCentre(benchmark::State& state) {
  MirrorCenterDetector det;
  const MirrorCircle prior = frame().circle;
  for (auto _ : state) benchmark::DoNotOptimize(det.detect(frame().image, prior));
}
BENCHMARK(BM_MirrorCentre)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RadialLines(benchmark::State& state) {
  LineExtractor ex;
  std::vector<VerticalLine> lines;
  ex.extract(frame().image, frame().circle, lines);
  for (auto _ : state) {
    ex.extract(frame().image, frame().circle, lines);
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}
BENCHMARK(BM_RadialLines)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RadialLines_Masked(benchmark::State& state) {
  LineExtractor ex;
  ex.set_mask(mask());
  std::vector<VerticalLine> lines;
  ex.extract(frame().image, frame().circle, lines);
  for (auto _ : state) {
    ex.extract(frame().image, frame().circle, lines);
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}
BENCHMARK(BM_RadialLines_Masked)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Descriptors(benchmark::State& state) {
  LineExtractor ex;
  std::vector<VerticalLine> lines;
  ex.extract(frame().image, frame().circle, lines);
  DescriptorExtractor d;
  DescriptorMatrix m;
  for (auto _ : state) {
    d.compute(frame().image, frame().circle, lines, m);
    benchmark::DoNotOptimize(m.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}
BENCHMARK(BM_Descriptors)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Descriptors_Masked(benchmark::State& state) {
  LineExtractor ex;
  std::vector<VerticalLine> lines;
  ex.extract(frame().image, frame().circle, lines);
  DescriptorExtractor d;
  d.set_mask(mask());
  DescriptorMatrix m;
  for (auto _ : state) {
    d.compute(frame().image, frame().circle, lines, m);
    benchmark::DoNotOptimize(m.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}
BENCHMARK(BM_Descriptors_Masked)->Unit(benchmark::kMillisecond)->UseRealTime();

// The front end on an image file with its sensor.yaml (environment OMNIVERT_BENCH_IMAGE and
// OMNIVERT_BENCH_SENSOR; skipped without them): the C++ side of the Python module's overhead
// (python/bench/extract_overhead.py times FeaturePipeline.process on the same file).
void BM_FrontEnd_File(benchmark::State& state) {
  const char* image_path = std::getenv("OMNIVERT_BENCH_IMAGE");
  const char* sensor_path = std::getenv("OMNIVERT_BENCH_SENSOR");
  if (image_path == nullptr || sensor_path == nullptr) {
    state.SkipWithError("OMNIVERT_BENCH_IMAGE and OMNIVERT_BENCH_SENSOR not set");
    return;
  }
  const cv::Mat image = read_image(image_path);
  FeaturePipeline pipe(load_camera_geometry(sensor_path));
  FrameFeatures f;
  pipe.process(image, f);  // first frame: rim estimation
  for (auto _ : state) {
    pipe.process(image, f);
    benchmark::DoNotOptimize(f.descriptors.data());
  }
  state.counters["lines"] = static_cast<double>(f.lines.size());
}
BENCHMARK(BM_FrontEnd_File)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_Peer_ORB(benchmark::State& state) {
  auto orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> kp;
  cv::Mat desc;
  for (auto _ : state) {
    orb->detectAndCompute(frame().image, cv::noArray(), kp, desc);
    benchmark::DoNotOptimize(desc.data);
  }
  state.counters["keypoints"] = static_cast<double>(kp.size());
}
BENCHMARK(BM_Peer_ORB)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Peer_LBD(benchmark::State& state) {
  auto bd = cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor();
  std::vector<cv::line_descriptor::KeyLine> lines;
  cv::Mat desc;
  for (auto _ : state) {
    lines.clear();
    bd->detect(frame().image, lines);
    bd->compute(frame().image, lines, desc);
    benchmark::DoNotOptimize(desc.data);
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}
BENCHMARK(BM_Peer_LBD)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
