// omnivert study: the paper's descriptor study (Sec. 5-6) and baselines, as CSV and PNG
// files in --out DIR (docs/study.md).
//   study similarity IMAGE   similarity matrices, ours / SSD / ZNCC (Figs. 9-12)
//   study sensitivity DATA   % correct NN vs clip, noise, bins/areas; rule PDFs (Figs. 13-18;
//                            eval/sensitivity_study.hpp)
//   study baselines DATA     precision/recall of ours, ZNCC and LBD on the same frames
//   study real-images DIR    lines, rotation and lighting repeatability on real images
//                            (tools/cmd_study_real.cpp, eval/real_image_study.hpp)

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "core/progress.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/eval/descriptor_study.hpp"
#include "omnivert/eval/sensitivity_study.hpp"
#include "omnivert/eval/similarity_study.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/match/matcher.hpp"
#include "omnivert/viz/plot.hpp"
#include "pipeline_options.hpp"

namespace omnivert::cli {

namespace {

namespace fs = std::filesystem;

std::string f6(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

void ensure_dir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw InputError(dir, 0, "cannot create the output folder");
}

std::string out_path(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

void write_matrix_csv(const std::string& path,
                      const cv::Mat1f& m,
                      const std::vector<double>& bearings) {
  std::ostringstream s;
  s << "#bearing [deg]";
  for (double b : bearings) s << ',' << f6(rad2deg(wrap_positive(b)));
  s << '\n';
  for (int i = 0; i < m.rows; ++i) {
    s << f6(rad2deg(wrap_positive(bearings[static_cast<std::size_t>(i)])));
    for (int j = 0; j < m.cols; ++j) s << ',' << f6(m(i, j));
    s << '\n';
  }
  write_text_atomic(path, s.str());
}

// ---------------------------------------------------------------- similarity
struct SimilarityArgs {
  std::string image, sensor, out;
  int steps = 360;
  double band = 10.0;
  FeaturePipelineOptions pipeline;
};

void run_similarity(const SimilarityArgs& a) {
  std::string why;
  if (!a.pipeline.IsValid(&why)) throw InputError("invalid options: " + why);
  const cv::Mat image = read_image(a.image);
  CameraGeometry geometry;
  if (!a.sensor.empty()) geometry = load_camera_geometry(a.sensor);
  FeaturePipeline pipe(geometry, a.pipeline);
  FrameFeatures f;
  if (!pipe.process(image, f, &why)) throw InputError(a.image, 0, why);
  ensure_dir(a.out);  // after the input is known to be good
  cv::Mat gray;
  FeaturePipeline::to_gray8(image, gray);
  eval::SimilarityOptions o;
  o.steps = a.steps;
  o.band_deg = a.band;
  o.descriptor = a.pipeline.descriptor;
  o.bearing_sign = geometry.bearing_sign;
  const eval::SimilarityResult r = eval::similarity_study(gray, f.circle, o);

  struct M {
    const char* name;
    const cv::Mat1f* m;
    const eval::Distinctiveness* d;
    const char* title;
    const char* scale;
  };
  const M ms[] = {{"descriptor",
                   &r.descriptor,
                   &r.descriptor_d,
                   "Our descriptor: distance (eq. 6)",
                   "distance"},
                  {"ssd", &r.ssd, &r.ssd_d, "SSD of the 2 r_a pattern (per pixel)", "SSD / px"},
                  {"zncc", &r.zncc, &r.zncc_d, "1 - ZNCC of the 2 r_a pattern", "1 - ZNCC"}};
  std::ostringstream sum;
  sum << "#measure,gap,median_gap,ambiguous_share,valley_deg,median_distance,band_deg\n";
  std::printf(
      "%s: centre (%.1f, %.1f), annulus %.1f..%.1f px, panorama %dx%d, pattern %d columns\n",
      a.image.c_str(),
      f.circle.center.x(),
      f.circle.center.y(),
      f.circle.r_min,
      f.circle.r_max,
      r.panorama.width(),
      r.panorama.rows(),
      r.pattern_columns);
  std::printf(
      "%-11s %8s %11s %10s %11s   (gap: mean nearest distance outside +-%.0f deg / median distance;"
      " ambiguous: rows with gap < %.2f)\n",
      "measure",
      "gap",
      "median_gap",
      "ambiguous",
      "valley[deg]",
      a.band,
      o.ambiguous_below);
  for (const auto& m : ms) {
    write_matrix_csv(
        out_path(a.out, std::string("similarity_") + m.name + ".csv"), *m.m, r.bearings);
    viz::HeatmapOptions h;
    char t[200];
    std::snprintf(t,
                  sizeof t,
                  "%s   gap %.2f, ambiguous %.0f%%, valley %.0f deg",
                  m.title,
                  m.d->gap,
                  100 * m.d->ambiguous,
                  m.d->valley_deg);
    h.title = t;
    h.scale_label = m.scale;
    h.cell = std::max(1, 720 / std::max(1, r.descriptor.rows));
    write_image_atomic(out_path(a.out, std::string("similarity_") + m.name + ".png"),
                       viz::draw_heatmap(*m.m, h));
    sum << m.name << ',' << f6(m.d->gap) << ',' << f6(m.d->median_gap) << ',' << f6(m.d->ambiguous)
        << ',' << f6(m.d->valley_deg) << ',' << f6(m.d->median_distance) << ',' << f6(a.band)
        << '\n';
    std::printf("%-11s %8.3f %11.3f %9.1f%% %11.1f\n",
                m.name,
                m.d->gap,
                m.d->median_gap,
                100 * m.d->ambiguous,
                m.d->valley_deg);
  }
  write_text_atomic(out_path(a.out, "similarity_summary.csv"), sum.str());
  // The panorama with the pattern of bearing 0 (Fig. 10).
  cv::Mat pano8, pano;
  r.panorama.image.convertTo(pano8, CV_8U);
  cv::cvtColor(pano8, pano, cv::COLOR_GRAY2BGR);
  const int c0 = static_cast<int>(
      std::lround(r.panorama.column_of_bearing(deg2rad(90.0)) - 0.5 * (r.pattern_columns - 1)));
  cv::rectangle(pano, cv::Rect(c0, 0, r.pattern_columns, r.panorama.rows()), {0, 0, 255}, 2);
  write_image_atomic(out_path(a.out, "panorama.png"), pano);
  std::printf(
      "wrote %s/similarity_{descriptor,ssd,zncc}.{csv,png}, similarity_summary.csv, panorama.png\n",
      a.out.c_str());
}

// ---------------------------------------------------------------- sensitivity
struct DatasetArgs {
  std::string dataset, out;
  double max_baseline = 2.0;
  int stride = 1;
  int max_frames = 0;
  std::uint64_t seed = 1;
  int threads = 0;
  FeaturePipelineOptions pipeline;
};

eval::StudySet load_set(const DatasetArgs& a, dataset::Dataset& data) {
  dataset::LoadOptions lo;
  lo.require_wheel = false;
  data = dataset::Dataset::load(a.dataset, lo);
  eval::StudyOptions so;
  so.max_baseline = a.max_baseline;
  so.frame_stride = a.stride;
  so.max_frames = a.max_frames;
  so.pipeline = a.pipeline;
  so.progress = Progress::enabled();
  so.threads = a.threads;
  eval::StudySet set = eval::load_study_set(data, so);
  std::printf(
      "%s: %zu frames, %zu lines (%zu associated to ground truth), %zu frame pairs within %.2f m\n",
      a.dataset.c_str(),
      set.frames.size(),
      set.lines(),
      set.associated(),
      set.frame_pairs(),
      a.max_baseline);
  return set;
}

void write_plot(const std::string& path,
                const std::vector<viz::PlotSeries>& s,
                const viz::PlotOptions& o) {
  write_image_atomic(path, viz::draw_plot(s, o));
}

void run_sensitivity(const DatasetArgs& a) {
  dataset::Dataset data;
  const eval::StudySet set = load_set(a, data);  // validates the input before any output exists
  ensure_dir(a.out);
  eval::SensitivityStudyOptions o;
  o.descriptor = a.pipeline.descriptor;
  o.max_baseline = a.max_baseline;
  o.seed = a.seed;
  eval::run_sensitivity_study(set, o, a.out, stdout);
  std::printf(
      "wrote %s/sensitivity_{clip,noise,bins}.{csv,png}, rule{1,2,3}_pdf.{csv,png}, rules.csv\n",
      a.out.c_str());
}

// ---------------------------------------------------------------- baselines
void run_baselines(const DatasetArgs& a) {
  dataset::Dataset data;
  const eval::StudySet set = load_set(a, data);  // validates the input before any output exists
  ensure_dir(a.out);
  std::vector<eval::MethodFeatures> methods;
  methods.push_back(eval::describe_ours(set, a.pipeline.descriptor, 0.0, a.seed));
  methods.push_back(eval::describe_zncc(set));
  methods.push_back(eval::describe_lbd_on_our_lines(set));
  eval::LbdOptions lo;
  methods.push_back(eval::describe_lbd_segments(set, data, lo, deg2rad(1.0)));
  lo.use_lsd = true;
  methods.push_back(eval::describe_lbd_segments(set, data, lo, deg2rad(1.0)));

  const std::vector<double> levels = {0.5, 0.6, 0.7, 0.8, 0.9};
  std::ostringstream bs, cs;
  bs << "#method,lines_per_frame,queries_per_frame,frame_pair_queries,nn_database_percent,average_"
        "precision,max_recall";
  for (double r : levels) bs << ",precision_at_recall_" << f6(r);
  bs << '\n';
  cs << "#method,ratio_threshold,precision,recall\n";
  std::vector<viz::PlotSeries> series;
  std::printf(
      "%-14s %6s %7s %8s %7s %6s %7s", "method", "lines", "queries", "NN db %", "AP", "max R", "");
  for (double r : levels) std::printf(" P@R%.1f", r);
  std::printf("\n");
  for (std::size_t mi = 0; mi < methods.size(); ++mi) {
    const auto& m = methods[mi];
    std::size_t lines = 0, queries = 0;
    for (const auto& ids : m.ids) {
      lines += ids.size();
      for (int id : ids) queries += id >= 0;
    }
    const auto records = eval::match_frame_pairs(set, m);
    const auto full = eval::precision_recall(records, 0);
    const auto nn = eval::nearest_neighbour_score(set, m);
    const double ap = eval::average_precision(full);
    const double max_r = full.empty() ? 0.0 : full.back().recall;
    const double nf = static_cast<double>(set.frames.size());
    bs << m.name << ',' << f6(lines / nf) << ',' << f6(queries / nf) << ',' << records.size() << ','
       << f6(nn.percent()) << ',' << f6(ap) << ',' << f6(max_r);
    std::printf("%-14s %6.1f %7.1f %7.2f%% %7.4f %6.3f %7s",
                m.name.c_str(),
                lines / nf,
                queries / nf,
                nn.percent(),
                ap,
                max_r,
                "");
    for (double r : levels) {
      const double p = eval::precision_at_recall(full, r);
      bs << ',' << (std::isnan(p) ? std::string("") : f6(p));
      if (std::isnan(p)) {
        std::printf(" %6s", "-");
      } else {
        std::printf(" %6.3f", p);
      }
    }
    bs << '\n';
    std::printf("\n");
    viz::PlotSeries s{m.name, {}, {}, viz::plot_color(static_cast<int>(mi)), false};
    for (const auto& p : eval::precision_recall(records, 300)) {
      cs << m.name << ',' << f6(p.threshold) << ',' << f6(p.precision) << ',' << f6(p.recall)
         << '\n';
      s.x.push_back(p.recall), s.y.push_back(p.precision);
    }
    series.push_back(s);
    if (mi == 0) {
      const MatchOptions F;
      const auto op = eval::rules_operating_point(records, F.f1, F.f2, F.f3);
      bs << "ours_three_rules,,,,,,," << f6(op.precision) << ',' << f6(op.recall)
         << "  # precision, recall at F1, F2, F3\n";
      std::printf("%-14s precision %.3f at recall %.3f (F1 %.2f, F2 %.2f, F3 %.2f)\n",
                  "ours 3 rules",
                  op.precision,
                  op.recall,
                  F.f1,
                  F.f2,
                  F.f3);
    }
  }
  write_text_atomic(out_path(a.out, "baselines.csv"), bs.str());
  write_text_atomic(out_path(a.out, "baselines_pr.csv"), cs.str());
  viz::PlotOptions po{"Precision-recall, ratio test nearest / second (frame pairs within baseline)",
                      "recall",
                      "precision"};
  po.x_lo = 0, po.x_hi = 1, po.y_lo = 0, po.y_hi = 1.02;
  po.legend_bottom = true;
  write_plot(out_path(a.out, "baselines_pr.png"), series, po);
  std::printf("wrote %s/baselines.csv, baselines_pr.{csv,png}\n", a.out.c_str());
}

void add_dataset_options(CLI::App* cmd, DatasetArgs& a) {
  cmd->add_option("DATASET", a.dataset, "Dataset with ground_truth/lines.csv and poses.csv")
      ->required();
  cmd->add_option("--out", a.out, "Output folder (created)")->required();
  cmd->add_option("--max-baseline",
                  a.max_baseline,
                  "Compare frames up to this far apart [m] (Sec. 6.0.1: 2)")
      ->check(kPositive)
      ->capture_default_str();
  cmd->add_option("--stride", a.stride, "Use every n-th image")
      ->check(kPositive)
      ->capture_default_str();
  cmd->add_option("--max-frames", a.max_frames, "Use at most this many images (0: all)")
      ->check(kNonNegative)
      ->capture_default_str();
  cmd->add_option("--seed", a.seed, "Seed of the image noise (Fig. 14)")->capture_default_str();
  add_threads_option(cmd, a.threads);
  add_pipeline_options(cmd, a.pipeline);
  cmd->add_flag("!--linear-intensity",
                a.pipeline.descriptor.log_intensity,
                "Gradients of the grey level I (the paper) instead of log(2 + I)")
      ->group(kDescriptorGroup);
}

}  // namespace

void add_study_command(CLI::App& app) {
  CLI::App* study = app.add_subcommand(
      "study", "The paper's descriptor study (Sec. 5-6) and baselines, as CSV and PNG");
  study->require_subcommand(1);

  auto s = std::make_shared<SimilarityArgs>();
  CLI::App* sim = study->add_subcommand(
      "similarity", "Similarity matrices of one image: ours, SSD, ZNCC (Figs. 9-12)");
  sim->add_option("IMAGE", s->image, "Catadioptric image")->required();
  sim->add_option("--sensor", s->sensor, "cam0/sensor.yaml: centre, r_min, r_max, bearing_sign");
  sim->add_option("--out", s->out, "Output folder (created)")->required();
  sim->add_option("--steps", s->steps, "Bearings over 360 degrees (the paper: 360)")
      ->check(CLI::Range(12, 1440))
      ->capture_default_str();
  sim->add_option("--band", s->band, "Degrees around the diagonal left out of the distinctiveness")
      ->check(CLI::Range(0.0, 90.0))
      ->capture_default_str();
  add_pipeline_options(sim, s->pipeline);
  sim->callback([s] { run_similarity(*s); });

  auto d = std::make_shared<DatasetArgs>();
  CLI::App* sens = study->add_subcommand("sensitivity",
                                         "% correct nearest neighbour vs clip, noise, bins/areas; "
                                         "PDFs of the three rules (Figs. 13-18)");
  add_dataset_options(sens, *d);
  sens->callback([d] { run_sensitivity(*d); });

  auto b = std::make_shared<DatasetArgs>();
  CLI::App* base = study->add_subcommand(
      "baselines", "Precision/recall of ours, ZNCC and LBD on the same frames");
  add_dataset_options(base, *b);
  base->callback([b] { run_baselines(*b); });

  add_real_images_study(study);
}

}  // namespace omnivert::cli
