#include "omnivert/eval/sensitivity_study.hpp"

#include <algorithm>
#include <cstdarg>
#include <filesystem>
#include <sstream>
#include <vector>

#include "omnivert/image/image_io.hpp"
#include "omnivert/match/matcher.hpp"
#include "omnivert/viz/plot.hpp"

namespace omnivert::eval {

namespace {

std::string f6(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// printf to `report` unless it is null.
[[gnu::format(printf, 2, 3)]] void say(std::FILE* report, const char* format, ...) {
  if (!report) return;
  va_list args;
  va_start(args, format);
  std::vfprintf(report, format, args);
  va_end(args);
}

// Writes a study's files into one folder.
struct StudyOutput {
  std::string dir;
  std::string path(const std::string& name) const {
    return (std::filesystem::path(dir) / name).string();
  }
  void text(const std::string& name, const std::string& s) const {
    write_text_atomic(path(name), s);
  }
  void plot(const std::string& name,
            const std::vector<viz::PlotSeries>& series,
            const viz::PlotOptions& o) const {
    write_image_atomic(path(name), viz::draw_plot(series, o));
  }
};

viz::PlotOptions plot_options(const std::string& title,
                              const std::string& x_label,
                              const std::string& y_label) {
  viz::PlotOptions o;
  o.title = title;
  o.x_label = x_label;
  o.y_label = y_label;
  return o;
}

// Three scores per setting: the database NN of the paper, the frame-pair NN, and the
// frame-pair NN over baselines of 1 m to the maximum; and the ratio test's average precision.
struct Scores {
  NearestNeighbourScore db, pair, far;
  double ap = 0;
};

Scores score_setting(const StudySet& set,
                     const SensitivityStudyOptions& options,
                     const DescriptorOptions& d,
                     double noise) {
  const auto m = describe_ours(set, d, noise, options.seed);
  const auto rec = match_frame_pairs(set, m);
  Scores s;
  s.db = nearest_neighbour_score(set, m);
  s.pair = pair_nearest_score(set, rec);
  s.far = pair_nearest_score(set, rec, 1.0, options.max_baseline);
  s.ap = average_precision(precision_recall(rec, 0));
  return s;
}

// The CSV columns of the scores, and a row of them.
void write_score_header(std::ostringstream& o) {
  o << "queries_db,correct_db,percent_db,queries_pair,percent_pair,queries_pair_1m,percent_pair_"
       "1m,"
       "ratio_test_average_precision\n";
}

void write_score_row(std::ostringstream& o, const Scores& s) {
  o << s.db.queries << ',' << s.db.correct << ',' << f6(s.db.percent()) << ',' << s.pair.queries
    << ',' << f6(s.pair.percent()) << ',' << s.far.queries << ',' << f6(s.far.percent()) << ','
    << f6(s.ap) << '\n';
}

// The three scores' plot series, and a point of each.
std::vector<viz::PlotSeries> score_series(const std::string& suffix) {
  return std::vector<viz::PlotSeries>{
      {"database NN" + suffix, {}, {}, viz::plot_color(0)},
      {"frame-pair NN" + suffix, {}, {}, viz::plot_color(1)},
      {"frame-pair NN, 1-2 m" + suffix, {}, {}, viz::plot_color(2)}};
}

void add_scores(std::vector<viz::PlotSeries>& v, std::size_t at, double x, const Scores& s) {
  v[at].x.push_back(x), v[at].y.push_back(s.db.percent());
  v[at + 1].x.push_back(x), v[at + 1].y.push_back(s.pair.percent());
  v[at + 2].x.push_back(x), v[at + 2].y.push_back(s.far.percent());
}

// Fig. 13: clipping threshold.
void clip_study(const StudySet& set,
                const SensitivityStudyOptions& options,
                const StudyOutput& out,
                std::FILE* report) {
  const DescriptorOptions& base = options.descriptor;
  const std::vector<double> clips = {0.025, 0.05, 0.075, 0.1, 0.125, 0.15, 0.2, 0.3, 0.5, 1.0};
  std::ostringstream cs;
  cs << "#clip,";
  write_score_header(cs);
  auto sc = score_series("");
  say(report, "Fig. 13, clipping threshold (1.0 = no clipping)\n");
  for (double c : clips) {
    DescriptorOptions d = base;
    d.clip = c;
    const auto s = score_setting(set, options, d, 0.0);
    cs << f6(c) << ',';
    write_score_row(cs, s);
    add_scores(sc, 0, c, s);
    say(report,
        "  clip %-6g %6.2f%% %6.2f%% %6.2f%%  AP %.4f\n",
        c,
        s.db.percent(),
        s.pair.percent(),
        s.far.percent(),
        s.ap);
  }
  out.text("sensitivity_clip.csv", cs.str());
  viz::PlotOptions pc = plot_options(
      "Fig. 13: influence of clipping", "clipping threshold", "% correct nearest neighbour");
  pc.vertical_lines = {base.clip};
  pc.vertical_labels = {"default"};
  pc.legend_bottom = true;
  out.plot("sensitivity_clip.png", sc, pc);
}

// Fig. 14: Gaussian image noise, sigma = p% of 255.
void noise_study(const StudySet& set,
                 const SensitivityStudyOptions& options,
                 const StudyOutput& out,
                 std::FILE* report) {
  std::ostringstream ns;
  ns << "#noise_percent,sigma_grey,";
  write_score_header(ns);
  auto sn = score_series("");
  say(report, "Fig. 14, Gaussian image noise (sigma in %% of 255)\n");
  for (double p : {0.0, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0}) {
    const auto s = score_setting(set, options, options.descriptor, p / 100.0 * 255.0);
    ns << f6(p) << ',' << f6(p * 2.55) << ',';
    write_score_row(ns, s);
    add_scores(sn, 0, p, s);
    say(report,
        "  noise %4.1f%% %6.2f%% %6.2f%% %6.2f%%  AP %.4f\n",
        p,
        s.db.percent(),
        s.pair.percent(),
        s.far.percent(),
        s.ap);
  }
  out.text("sensitivity_noise.csv", ns.str());
  viz::PlotOptions pn = plot_options(
      "Fig. 14: influence of image noise", "noise sigma [% of 255]", "% correct nearest neighbour");
  pn.legend_bottom = true;
  out.plot("sensitivity_noise.png", sn, pn);
}

// Fig. 15: bins and areas; with the separation of the rule-3 ratio (average precision).
void bins_study(const StudySet& set,
                const SensitivityStudyOptions& options,
                const StudyOutput& out,
                std::FILE* report) {
  std::ostringstream bs;
  bs << "#bins,areas,size,";
  write_score_header(bs);
  std::vector<viz::PlotSeries> sb;
  say(report, "Fig. 15, orientation bins x areas\n");
  for (int areas : {3, 5}) {
    auto s3 = score_series(areas == 3 ? ", 3 areas" : ", 5 areas");
    for (auto& s : s3) s.dashed = areas == 5;
    for (int bins : {8, 16, 32}) {
      DescriptorOptions d = options.descriptor;
      d.bins = bins, d.areas = areas;
      const auto s = score_setting(set, options, d, 0.0);
      bs << bins << ',' << areas << ',' << d.size() << ',';
      write_score_row(bs, s);
      add_scores(s3, 0, bins, s);
      say(report,
          "  %2d bins, %d areas (%3d-D): %6.2f%% %6.2f%% %6.2f%%  AP %.4f\n",
          bins,
          areas,
          d.size(),
          s.db.percent(),
          s.pair.percent(),
          s.far.percent(),
          s.ap);
    }
    sb.insert(sb.end(), s3.begin(), s3.end());
  }
  out.text("sensitivity_bins.csv", bs.str());
  viz::PlotOptions pb = plot_options(
      "Fig. 15: orientation bins and areas", "orientation bins", "% correct nearest neighbour");
  pb.legend_bottom = true;
  pb.x_lo = 4, pb.x_hi = 52;  // room on the right for the legend
  out.plot("sensitivity_bins.png", sb, pb);
}

// Histogram densities of values (correct / incorrect) over [0, hi].
void pdf(const std::vector<double>& v,
         double hi,
         int bins,
         std::vector<double>& x,
         std::vector<double>& y) {
  x.assign(bins, 0), y.assign(bins, 0);
  const double w = hi / bins;
  for (int i = 0; i < bins; ++i) x[i] = (i + 0.5) * w;
  if (v.empty()) return;
  for (double t : v) {
    const int b = std::clamp(static_cast<int>(t / w), 0, bins - 1);
    y[b] += 1.0;
  }
  for (double& t : y) t /= (v.size() * w);
}

// One of Figs. 16-18: the densities of rule `rule`'s value (eqs. 8-10) for correct and
// incorrect nearest matches, and the shares the rule rejects at its threshold; a row of
// rules.csv into rs.
void rule_study(const std::vector<MatchRecord>& records,
                int rule,
                double threshold,
                const StudyOutput& out,
                std::ostringstream& rs,
                std::FILE* report) {
  const char* names[3] = {
      "nearest distance", "nearest / mean distance", "nearest / second-nearest distance"};
  const char* fig[3] = {"Fig. 16: rule 1", "Fig. 17: rule 2", "Fig. 18: rule 3"};
  std::vector<double> cv, iv;
  double hi = 0;
  for (const auto& r : records) {
    const double v = rule_value(r, rule);
    (r.correct() ? cv : iv).push_back(v);
    hi = std::max(hi, v);
  }
  hi = rule == 1 ? std::max(1.5, hi * 1.02) : 1.0;
  std::vector<double> x, yc, yi;
  pdf(cv, hi, 50, x, yc);
  pdf(iv, hi, 50, x, yi);
  std::ostringstream ps;
  ps << "#value,pdf_correct,pdf_incorrect\n";
  for (std::size_t i = 0; i < x.size(); ++i)
    ps << f6(x[i]) << ',' << f6(yc[i]) << ',' << f6(yi[i]) << '\n';
  out.text("rule" + std::to_string(rule) + "_pdf.csv", ps.str());
  const auto sh = rule_shares(records, rule, threshold);
  rs << rule << ',' << f6(sh.threshold) << ',' << sh.correct << ',' << sh.incorrect << ','
     << f6(sh.false_removed) << ',' << f6(sh.correct_lost) << '\n';
  char t[160];
  std::snprintf(t,
                sizeof t,
                "%s: removes %.0f%% of false, loses %.0f%% of correct",
                fig[rule - 1],
                100 * sh.false_removed,
                100 * sh.correct_lost);
  viz::PlotOptions po = plot_options(t, names[rule - 1], "probability density");
  po.x_lo = 0, po.x_hi = hi;
  po.y_lo = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    po.y_hi = std::max({po.y_hi, 1.08 * yc[i], 1.08 * yi[i]});
  if (!(po.y_hi > 0)) po.y_hi = 1;
  po.vertical_lines = {threshold};
  std::string label = "F";  // built by appends: GCC 12 warns falsely on "F" + std::string&&
  label += std::to_string(rule) + " = " + f6(threshold);
  po.vertical_labels = {label};
  out.plot("rule" + std::to_string(rule) + "_pdf.png",
           {{"correct matches", x, yc, viz::plot_color(2), false},
            {"incorrect matches", x, yi, viz::plot_color(3), false}},
           po);
  say(report,
      "  rule %d (F = %.2f): removes %5.1f%% of false matches, loses %5.1f%% of correct ones\n",
      rule,
      threshold,
      100 * sh.false_removed,
      100 * sh.correct_lost);
}

// Figs. 16-18: the three rules on the nearest matches of the frame pairs, and rules.csv.
void rules_study(const StudySet& set,
                 const SensitivityStudyOptions& options,
                 const StudyOutput& out,
                 std::FILE* report) {
  const auto records =
      match_frame_pairs(set, describe_ours(set, options.descriptor, 0.0, options.seed));
  const MatchOptions F;
  const double thr[3] = {F.f1, F.f2, F.f3};
  std::ostringstream rs;
  rs << "#rule,threshold,correct,incorrect,false_removed,correct_lost\n";
  std::int64_t n_correct = 0;
  for (const auto& r : records) n_correct += r.correct();
  say(report,
      "Figs. 16-18, %zu frame-pair queries, %.1f%% nearest correct\n",
      records.size(),
      records.empty() ? 0.0 : 100.0 * n_correct / records.size());
  for (int rule = 1; rule <= 3; ++rule) rule_study(records, rule, thr[rule - 1], out, rs, report);
  const auto all = rules_operating_point(records, F.f1, F.f2, F.f3);
  rs << "all,,,," << f6(all.precision) << ',' << f6(all.recall)
     << "  # precision, recall of the three rules together\n";
  say(report,
      "  all three rules: precision %.1f%%, recall %.1f%%\n",
      100 * all.precision,
      100 * all.recall);
  out.text("rules.csv", rs.str());
}

}  // namespace

void run_sensitivity_study(const StudySet& set,
                           const SensitivityStudyOptions& options,
                           const std::string& out_dir,
                           std::FILE* report) {
  const StudyOutput out{out_dir};
  say(report,
      "%% correct nearest neighbour: database (all frames within the baseline) / frame pairs / "
      "frame "
      "pairs 1-2 m apart; AP: average precision of the ratio test on frame pairs\n");
  clip_study(set, options, out, report);
  noise_study(set, options, out, report);
  bins_study(set, options, out, report);
  rules_study(set, options, out, report);
}

}  // namespace omnivert::eval
