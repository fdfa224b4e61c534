// The descriptor study's building blocks: the panorama against drawn geometry, SSD/ZNCC on
// known patches, the distinctiveness number, the precision/recall bookkeeping, and a tiny
// study on a simulated dataset.

#include <cmath>
#include <filesystem>
#include <limits>

#include <unistd.h>

#include <gtest/gtest.h>

#include "omnivert/core/angles.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/eval/descriptor_study.hpp"
#include "omnivert/eval/panorama.hpp"
#include "omnivert/eval/real_image_study.hpp"
#include "omnivert/eval/similarity_study.hpp"
#include "omnivert/sim/radial_pattern.hpp"
#include "omnivert/sim/simulator.hpp"
#include "omnivert/viz/plot.hpp"

namespace omnivert {
namespace {

// An image whose intensity is bright for image angles in [from, to) degrees and dark
// elsewhere, sampled 8x8 per pixel (the edges are radial lines at exact angles), with a bright
// ring of width 2 px at radius `ring`.
cv::Mat1b sector_image(Eigen::Vector2d c, double from, double to, double ring) {
  cv::Mat1b img(400, 420);
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) {
      double s = 0;
      for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b) {
          const double x = u - 0.5 + (a + 0.5) / 8 - c.x(), y = v - 0.5 + (b + 0.5) / 8 - c.y();
          const double ang = rad2deg(wrap_positive(std::atan2(y, x)));
          const double r = std::hypot(x, y);
          s += std::abs(r - ring) < 1.0 ? 250 : (ang >= from && ang < to ? 180 : 60);
        }
      img(v, u) = cv::saturate_cast<uchar>(s / 64);
    }
  return img;
}

// Sub-column position where a row crosses `level` between columns c0 and c1 (rising or falling).
double crossing(const cv::Mat1f& p, int row, int c0, int c1, double level) {
  for (int c = c0; c < c1; ++c) {
    const double a = p(row, c), b = p(row, c + 1);
    if ((a - level) * (b - level) <= 0 && a != b) return c + (level - a) / (b - a);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

TEST(Panorama, RadialEdgeAtBearingLandsInThatColumn) {
  const Eigen::Vector2d c(210.3, 199.6);
  const cv::Mat1b img = sector_image(c, 30.0, 135.0, 100.0);
  MirrorCircle circle;
  circle.center = c, circle.r_min = 40, circle.r_max = 150;
  eval::PanoramaOptions o;
  o.width = 360;  // one column per degree
  const eval::Panorama p = eval::unwrap_panorama(img, circle, o);
  ASSERT_EQ(p.width(), 360);
  ASSERT_EQ(p.rows(), 111);
  const double level = 120;  // midway between 60 and 180
  for (int row : {0, 20, 80, 110}) {
    if (std::abs(p.radius_of_row(row) - 100) < 3) continue;
    EXPECT_NEAR(crossing(p.image, row, 20, 40, level), 30.0, 0.25) << "row " << row;
    EXPECT_NEAR(crossing(p.image, row, 125, 145, level), 135.0, 0.25) << "row " << row;
  }
  // Column -> bearing and back.
  EXPECT_NEAR(rad2deg(p.bearing_of_column(30)), 30.0, 1e-9);
  EXPECT_NEAR(p.column_of_bearing(deg2rad(-90)), 270.0, 1e-9);
  // Radius -> row: the ring at r = 100 is row (150 - 100) = 50.
  double best = 0;
  int best_row = -1;
  for (int r = 0; r < p.rows(); ++r)
    if (p.image(r, 300) > best) best = p.image(r, 300), best_row = r;
  EXPECT_EQ(best_row, 50);
  EXPECT_NEAR(p.radius_of_row(50), 100.0, 1e-9);
  // A mirror-flipped camera: bearing b is image angle -b, so the edge at image angle 30 is
  // at bearing 330.
  o.bearing_sign = -1;
  const eval::Panorama q = eval::unwrap_panorama(img, circle, o);
  EXPECT_NEAR(crossing(q.image, 10, 320, 340, level), 330.0, 0.25);
  EXPECT_NEAR(crossing(q.image, 10, 215, 235, level), 225.0, 0.25);
}

TEST(Panorama, DefaultWidthIsAMultipleOf360AndPatternWraps) {
  cv::Mat1b img(300, 300);
  cv::randu(img, 0, 255);
  MirrorCircle circle;
  circle.center = {150, 150}, circle.r_min = 30, circle.r_max = 120;
  const eval::Panorama p = eval::unwrap_panorama(img, circle);
  EXPECT_EQ(p.width() % 360, 0);
  // 2 pi * 75 = 471 px of arc at the middle radius -> 360 columns.
  EXPECT_EQ(p.width(), 360);
  EXPECT_EQ(eval::paper_pattern_columns(p),
            static_cast<int>(std::lround(2 * 15.0 / (kTwoPi * 75 / 360))));
  const cv::Mat1f pat = eval::panorama_pattern(p, 0.0, 5);
  ASSERT_EQ(pat.cols, 5);
  for (int r = 0; r < p.rows(); r += 17) {
    EXPECT_FLOAT_EQ(pat(r, 0), p.image(r, 358));
    EXPECT_FLOAT_EQ(pat(r, 1), p.image(r, 359));
    EXPECT_FLOAT_EQ(pat(r, 2), p.image(r, 0));
    EXPECT_FLOAT_EQ(pat(r, 4), p.image(r, 2));
  }
  EXPECT_THROW(eval::unwrap_panorama(cv::Mat(), circle), std::invalid_argument);
  circle.r_min = 130;
  EXPECT_THROW(eval::unwrap_panorama(img, circle), std::invalid_argument);
}

TEST(PatchSimilarity, IdenticalAndAffinePatches) {
  cv::Mat1f a(20, 7);
  cv::randu(a, 0, 255);
  EXPECT_DOUBLE_EQ(eval::ssd_per_pixel(a, a), 0.0);
  EXPECT_NEAR(eval::zncc(a, a), 1.0, 1e-9);
  const cv::Mat1f b = a * 2.0 + 10.0;  // gain and offset: ZNCC is invariant, SSD is not
  EXPECT_NEAR(eval::zncc(a, b), 1.0, 1e-9);
  EXPECT_GT(eval::ssd_per_pixel(a, b), 100.0);
  const cv::Mat1f neg = 255.0 - a;
  EXPECT_NEAR(eval::zncc(a, neg), -1.0, 1e-9);
  cv::Mat1f c = a.clone();
  c(3, 3) += 10.0f;
  EXPECT_NEAR(eval::ssd_per_pixel(a, c), 100.0 / 140.0, 1e-6);
  const cv::Mat1f flat(20, 7, 5.0f);
  EXPECT_EQ(eval::zncc(a, flat), 0.0);
}

TEST(Similarity, DistinctivenessSeesRepetition) {
  // 36 rows; rows i and i + 18 are identical descriptors (a repeated pattern half a turn away).
  DescriptorMatrix d(36, 4);
  cv::RNG rng(3);
  for (int i = 0; i < 18; ++i)
    for (int k = 0; k < 4; ++k) d(i, k) = d(i + 18, k) = static_cast<float>(rng.uniform(0.0, 1.0));
  const cv::Mat1f s = eval::descriptor_distance_matrix(d);
  EXPECT_FLOAT_EQ(s(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(s(3, 21), 0.0f);
  EXPECT_FLOAT_EQ(s(2, 5), s(5, 2));
  const eval::Distinctiveness rep = eval::distinctiveness(s, 10.0, 0.25);
  EXPECT_EQ(rep.ambiguous, 1.0);
  EXPECT_EQ(rep.gap, 0.0);
  for (int i = 18; i < 36; ++i)
    for (int k = 0; k < 4; ++k) d(i, k) = static_cast<float>(rng.uniform(0.0, 1.0));
  const eval::Distinctiveness uniq =
      eval::distinctiveness(eval::descriptor_distance_matrix(d), 10.0, 0.25);
  EXPECT_GT(uniq.gap, 0.1);
  EXPECT_LT(uniq.ambiguous, 0.5);
}

TEST(Similarity, MatricesOfADrawnImage) {
  sim::RadialPatternOptions po;
  po.seed = 11;
  const auto pat = sim::draw_radial_pattern(po);
  const MirrorCircle circle = pat.circle;
  eval::SimilarityOptions o;
  o.steps = 72;
  const eval::SimilarityResult r = eval::similarity_study(pat.image, circle, o);
  ASSERT_EQ(r.descriptor.rows, 72);
  ASSERT_EQ(r.ssd.cols, 72);
  for (int i = 0; i < 72; i += 7) {
    EXPECT_FLOAT_EQ(r.descriptor(i, i), 0.0f);
    EXPECT_FLOAT_EQ(r.ssd(i, i), 0.0f);
    EXPECT_NEAR(r.zncc(i, i), 0.0f, 1e-5);
    EXPECT_FLOAT_EQ(r.zncc(i, (i + 30) % 72), r.zncc((i + 30) % 72, i));
  }
  EXPECT_GT(r.descriptor_d.gap, 0.0);
  EXPECT_GT(r.pattern_columns, 10);
  // Pictures: a heat map with its colour bar, a plot.
  viz::HeatmapOptions h;
  h.title = "test";
  const cv::Mat img = viz::draw_heatmap(r.descriptor, h);
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_GT(img.cols, 72 * 2 + 100);
  const cv::Mat plot =
      viz::draw_plot({{"a", {0, 1, 2}, {1, 3, 2}, viz::plot_color(0)}}, {"t", "x", "y"});
  EXPECT_EQ(plot.size(), cv::Size(900, 600));
}

TEST(Study, PrecisionRecallBookkeeping) {
  // Four queries: ratios 0.2 (correct), 0.5 (wrong), 0.6 (correct), 0.9 (wrong, line absent).
  std::vector<eval::MatchRecord> r(4);
  const double ratio[4] = {0.2, 0.5, 0.6, 0.9};
  for (int i = 0; i < 4; ++i) {
    r[i].query_id = 1, r[i].candidates = 3, r[i].second = 1.0, r[i].nearest = ratio[i],
    r[i].mean = 1.0;
    r[i].nearest_id = (i % 2 == 0) ? 1 : 2;
    r[i].has_true = i < 3;
  }
  const auto pr = eval::precision_recall(r, 0);
  ASSERT_EQ(pr.size(), 4u);
  EXPECT_DOUBLE_EQ(pr[0].precision, 1.0);
  EXPECT_DOUBLE_EQ(pr[0].recall, 1.0 / 3);
  EXPECT_DOUBLE_EQ(pr[2].precision, 2.0 / 3);
  EXPECT_DOUBLE_EQ(pr[2].recall, 2.0 / 3);
  EXPECT_DOUBLE_EQ(eval::precision_at_recall(pr, 0.5), 2.0 / 3);
  EXPECT_TRUE(std::isnan(eval::precision_at_recall(pr, 0.9)));
  EXPECT_NEAR(eval::average_precision(pr), 1.0 / 3 + (1.0 / 3) * (2.0 / 3), 1e-12);
  const auto s3 = eval::rule_shares(r, 3, 0.55);  // rejects 0.6 (correct) and 0.9 (wrong)
  EXPECT_DOUBLE_EQ(s3.false_removed, 0.5);
  EXPECT_DOUBLE_EQ(s3.correct_lost, 0.5);
  const auto op = eval::rules_operating_point(r, 10.0, 10.0, 0.55);
  EXPECT_DOUBLE_EQ(op.precision, 0.5);
  EXPECT_DOUBLE_EQ(op.recall, 1.0 / 3);
}

// Three frames on a line, 0, 1.5 and 3 m: frames 0-1 and 1-2 are within 2 m, 0-2 are not.
// Lines are points on a number line; the distance is |a - b| (a hand-made method).
TEST(Study, NearestNeighbourProtocol) {
  eval::StudySet set;
  set.frames.resize(3);
  for (int k = 0; k < 3; ++k) set.frames[k].x = 1.5 * k;
  set.neighbours = {{1}, {0, 2}, {1}};
  // frame: values (ids)
  const std::vector<std::vector<double>> v = {
      {0.0, 10.0, 20.0}, {0.4, 10.9, 13.0, 50.0}, {0.2, 50.0}};
  eval::MethodFeatures m;
  m.ids = {{1, 2, 3}, {1, 2, 9, -1}, {1, 7}};
  m.distances = [&](int k, int l) {
    cv::Mat1f d(static_cast<int>(v[k].size()), static_cast<int>(v[l].size()));
    for (int i = 0; i < d.rows; ++i)
      for (int j = 0; j < d.cols; ++j) d(i, j) = static_cast<float>(std::abs(v[k][i] - v[l][j]));
    return d;
  };
  // Database NN (frames within 2 m):
  //  frame 0: id 1 -> 0.4 (id 1) correct; id 2 (10) -> 10.9 (id 2) correct; id 3 (20) -> 13
  //           (id 9) wrong, and id 3 is nowhere in frame 1: not counted.
  //  frame 1: id 1 (0.4) -> 0.2 (frame 2, id 1) correct; id 2 (10.9) -> 10 (id 2) correct;
  //           id 9 (13): absent elsewhere, not counted; the -1 line is never a query.
  //  frame 2: id 1 (0.2) -> 0.4 (id 1) correct; id 7 (50) -> 50 (id -1) wrong, absent: not
  //           counted.
  const auto nn = eval::nearest_neighbour_score(set, m);
  EXPECT_EQ(nn.queries, 5);
  EXPECT_EQ(nn.correct, 5);
  // Frame pairs: 4 ordered pairs; queries 3 + 3 + 3 + 2 = 11 records.
  const auto rec = eval::match_frame_pairs(set, m);
  ASSERT_EQ(rec.size(), 11u);
  int with_true = 0, correct = 0;
  for (const auto& r : rec) with_true += r.has_true, correct += r.correct();
  // Present: (0->1) ids 1, 2; (1->0) 1, 2; (1->2) 1; (2->1) 1: 6 records.
  EXPECT_EQ(with_true, 6);
  // (1->2): id 2 (10.9) -> 0.2 (id 1) wrong, id 9 (13) -> 0.2 wrong; the rest with the line
  // present are right; (0->1) id 3 -> 13 (id 9) wrong; (2->1) id 7 -> 50 (id -1) wrong.
  EXPECT_EQ(correct, 6);
  const auto pair = eval::pair_nearest_score(set, rec);
  EXPECT_EQ(pair.queries, 6);
  EXPECT_EQ(pair.correct, 6);
  // The first record: frame 0, id 1 against frame 1: distances 0.4, 10.9, 13, 50.
  EXPECT_EQ(rec[0].query_id, 1);
  EXPECT_FLOAT_EQ(static_cast<float>(rec[0].nearest), 0.4f);
  EXPECT_FLOAT_EQ(static_cast<float>(rec[0].second), 10.9f);
  EXPECT_NEAR(rec[0].mean, (0.4 + 10.9 + 13.0 + 50.0) / 4, 1e-5);
  EXPECT_EQ(rec[0].candidates, 4);
  // Baselines: only the 1.5 m pairs remain in [1, 2] m; none in [2, 3].
  EXPECT_EQ(eval::pair_nearest_score(set, rec, 1.0, 2.0).queries, 6);
  EXPECT_EQ(eval::pair_nearest_score(set, rec, 2.0, 3.0).queries, 0);
}

TEST(Study, TinySimulatedRun) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("omnivert_study_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  sim::SimConfig cfg;
  cfg.max_frames = 6;
  sim::simulate(
      sim::world_preset("corridor"), sim::load_trajectory("paper"), cfg, (dir / "run").string());
  dataset::LoadOptions lo;
  lo.require_wheel = false;
  const auto data = dataset::Dataset::load((dir / "run").string(), lo);
  eval::StudyOptions so;
  so.progress = false;
  const eval::StudySet set = eval::load_study_set(data, so);
  ASSERT_EQ(set.frames.size(), 6u);
  EXPECT_GT(set.associated(), 18u);   // about 4-5 long lines per frame (50% rule)
  EXPECT_EQ(set.frame_pairs(), 30u);  // 6 frames 3.8 cm apart: all within 2 m
  const auto ours = eval::describe_ours(set, {}, 0.0);
  const auto nn = eval::nearest_neighbour_score(set, ours);
  EXPECT_GT(nn.queries, 18);
  EXPECT_GT(nn.percent(), 90.0);  // 20 cm of motion at most: nearly all right
  const auto rec = eval::match_frame_pairs(set, ours);
  EXPECT_GT(rec.size(), 100u);
  // Noise lowers the score (or keeps it), never raises it above the clean one by much.
  const auto noisy = eval::nearest_neighbour_score(set, eval::describe_ours(set, {}, 0.10 * 255));
  EXPECT_EQ(noisy.queries, nn.queries);
  EXPECT_LE(noisy.correct, nn.correct + 2);
  const auto z = eval::describe_zncc(set);
  EXPECT_EQ(z.ids, ours.ids);
  EXPECT_GT(eval::nearest_neighbour_score(set, z).percent(), 50.0);
  const auto lbd = eval::describe_lbd_on_our_lines(set);
  EXPECT_EQ(lbd.ids, ours.ids);
  const auto seg = eval::describe_lbd_segments(set, data, {}, deg2rad(1.0));
  ASSERT_EQ(seg.ids.size(), 6u);
  // LBD distances of a frame with itself: 0 on the diagonal.
  const cv::Mat1f self = seg.distances(0, 0);
  for (int i = 0; i < self.rows; ++i) EXPECT_EQ(self(i, i), 0.0f);
  fs::remove_all(dir);
}

// The real-image study on a drawn image with known edges and its circle given: the edges are
// found again at their rotated angle, and a nearest neighbour among the same polarity is
// right at least as often as one among all lines (a subset of the candidates holding it).
TEST(RealImageStudy, DrawnEdgesAreFoundAgainUnderRotationAndLighting) {
  sim::RadialPatternOptions po;
  po.seed = 3;
  const auto p = sim::draw_radial_pattern(po);
  CameraGeometry g;
  g.width = p.image.cols, g.height = p.image.rows;
  g.center = p.circle.center;
  g.r_min = p.circle.r_min, g.r_max = p.circle.r_max;
  eval::RealImageStudyOptions o;
  o.strongest = 10;
  const eval::RealImageResult r = eval::study_real_image("drawn", p.image, g, o);
  ASSERT_TRUE(r.ok) << r.error;
  std::printf("drawn: %d lines; rotation found %.1f %%, NN %.1f %%, same polarity %.1f %%\n",
              r.lines,
              r.rotation[1].found_percent(),
              r.rotation[1].nn_percent(),
              r.rotation[1].nn_polarity_percent());
  ASSERT_GE(r.lines, 10);
  EXPECT_EQ(r.rotation[1].looked_for, 10 * 4);
  EXPECT_GE(r.rotation[1].found_percent(), 95.0);
  EXPECT_EQ(r.lighting[1].looked_for, 10 * 5);
  EXPECT_GE(r.lighting[1].found_percent(), 95.0);
  for (const eval::RepeatCount& c : {r.rotation[1], r.lighting[1]}) {
    EXPECT_LE(c.nn_correct, c.nn_correct_polarity);
    EXPECT_LE(c.nn_correct_polarity, c.found);
  }
  const std::string csv = eval::real_image_csv({r});
  EXPECT_NE(csv.find("rotation_given_nn_correct_same_polarity"), std::string::npos);
}

}  // namespace
}  // namespace omnivert
