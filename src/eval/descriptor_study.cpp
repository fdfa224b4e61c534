#include "omnivert/eval/descriptor_study.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include <opencv2/imgproc.hpp>
#include <opencv2/line_descriptor.hpp>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/eval/panorama.hpp"

namespace omnivert::eval {

namespace {

using RowMat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The ground-truth id of a bearing: the nearest true line within the tolerance; -1 when there
// is none or when two true lines are within it (ambiguous).
int associate(double bearing, std::span<const dataset::LineRecord> truth, double tol) {
  int id = -1, within = 0;
  double best = tol;
  for (const auto& t : truth) {
    const double d = std::abs(angle_diff(bearing, t.bearing));
    if (d <= tol) {
      ++within;
      if (d <= best) best = d, id = t.line_id;
    }
  }
  return within == 1 ? id : -1;
}

// Euclidean distances between the rows of a and b (eq. 6).
cv::Mat1f euclidean(const RowMat& a, const RowMat& b) {
  cv::Mat1f out(static_cast<int>(a.rows()), static_cast<int>(b.rows()));
  if (a.rows() == 0 || b.rows() == 0) return out;
  const Eigen::VectorXf na = a.rowwise().squaredNorm(), nb = b.rowwise().squaredNorm();
  const RowMat g = a * b.transpose();
  for (int i = 0; i < out.rows; ++i)
    for (int j = 0; j < out.cols; ++j)
      out(i, j) = std::sqrt(std::max(0.0f, na(i) + nb(j) - 2.0f * g(i, j)));
  return out;
}

}  // namespace

std::size_t StudySet::lines() const {
  std::size_t n = 0;
  for (const auto& f : frames) n += f.lines.size();
  return n;
}

std::size_t StudySet::associated() const {
  std::size_t n = 0;
  for (const auto& f : frames)
    for (const auto& l : f.lines) n += l.line_id >= 0;
  return n;
}

std::size_t StudySet::frame_pairs() const {
  std::size_t n = 0;
  for (const auto& v : neighbours) n += v.size();
  return n;
}

StudySet load_study_set(const dataset::Dataset& data, const StudyOptions& o) {
  namespace fs = std::filesystem;
  if (!data.ground_truth_error().empty()) throw InputError(data.ground_truth_error());
  const auto& gt = data.ground_truth();
  const std::string gt_dir = (fs::path(data.root()) / "ground_truth").string();
  if (!gt || !gt->has_lines)
    throw InputError(
        gt_dir + "/lines.csv", 0, "file not found: the study needs the ground-truth lines");
  if (!gt->has_poses)
    throw InputError(gt_dir + "/poses.csv",
                     0,
                     "file not found: the study needs the robot positions (baselines)");
  std::string why;
  if (!o.pipeline.IsValid(&why)) throw InputError("invalid pipeline options: " + why);
  StudySet set;
  set.bearing_sign = data.camera().bearing_sign;
  FeaturePipeline pipe(data.camera(), o.pipeline);
  std::vector<std::size_t> picks;
  for (std::size_t i = 0; i < data.size();
       i += static_cast<std::size_t>(std::max(1, o.frame_stride))) {
    picks.push_back(i);
    if (o.max_frames > 0 && static_cast<int>(picks.size()) >= o.max_frames) break;
  }
  // The images read on the threads; each mirror circle located in order (its search starts
  // from the previous frame's, Sec. 2 step 1); lines and descriptors on the threads again,
  // one describer each (pipeline/frame_source.cpp does the same for tracking).
  const int threads = resolve_threads(o.threads);
  const std::size_t m = picks.size();
  std::vector<cv::Mat> images(m), grays(m);
  std::vector<MirrorCircle> circles(m);
  std::vector<FrameFeatures> features(m);
  parallel_for(m, threads, [&](std::size_t n, int) { images[n] = data.image(picks[n]); });
  Progress progress("study: extracting lines", m);
  for (std::size_t n = 0; n < m; ++n) {
    if (!pipe.locate(images[n], grays[n], circles[n], &why))
      throw InputError(data.images()[picks[n]].path, 0, why);
    if (o.progress) progress.update(n + 1);
  }
  std::vector<FrameDescriber> describers;
  for (int t = 0; t < threads; ++t) describers.push_back(pipe.make_describer());
  parallel_for(m, threads, [&](std::size_t n, int worker) {
    describers[static_cast<std::size_t>(worker)].describe(grays[n], circles[n], features[n]);
    grays[n].release();
  });
  for (std::size_t n = 0; n < m; ++n) {
    const std::size_t i = picks[n];
    const FrameFeatures& f = features[n];
    StudyFrame fr;
    fr.index = i;
    fr.image = images[n];
    images[n].release();
    fr.circle = f.circle;
    if (i >= gt->poses.size())
      throw InputError(gt_dir + "/poses.csv", 0, "fewer poses than images");
    fr.x = gt->poses[i].x;
    fr.y = gt->poses[i].y;
    const auto truth = gt->lines_in_frame(i);
    for (const auto& l : f.lines)
      fr.lines.push_back({associate(l.bearing, truth, o.association_tolerance),
                          l.image_angle,
                          l.bearing,
                          l.r_inner,
                          l.r_outer});
    set.frames.push_back(std::move(fr));
  }
  if (o.progress) progress.finish();
  set.neighbours.resize(set.frames.size());
  for (std::size_t k = 0; k < set.frames.size(); ++k)
    for (std::size_t l = 0; l < set.frames.size(); ++l)
      if (k != l && std::hypot(set.frames[k].x - set.frames[l].x,
                               set.frames[k].y - set.frames[l].y) <= o.max_baseline)
        set.neighbours[k].push_back(static_cast<int>(l));
  if (set.associated() == 0)
    throw InputError(gt_dir + "/lines.csv",
                     0,
                     "no extracted line is within the association tolerance of a true line");
  return set;
}

MethodFeatures describe_ours(const StudySet& set,
                             const DescriptorOptions& options,
                             double noise_sigma,
                             std::uint64_t seed) {
  auto mats = std::make_shared<std::vector<RowMat>>(set.frames.size());
  MethodFeatures m;
  m.name = "ours";
  DescriptorExtractor ex(options);
  cv::Mat1b noisy;
  for (std::size_t k = 0; k < set.frames.size(); ++k) {
    const auto& fr = set.frames[k];
    std::vector<double> angles;
    std::vector<int> ids;
    for (const auto& l : fr.lines) angles.push_back(l.image_angle), ids.push_back(l.line_id);
    m.ids.push_back(ids);
    const cv::Mat1b* img = &fr.image;
    if (noise_sigma > 0) {
      cv::Mat1f n(fr.image.size());
      cv::RNG rng(seed * 1000003ULL + fr.index);
      rng.fill(n, cv::RNG::NORMAL, 0.0, noise_sigma);
      cv::Mat1f g;
      fr.image.convertTo(g, CV_32F);
      g += n;
      g.convertTo(noisy, CV_8U);  // rounds and clips to 0..255 (saturation)
      img = &noisy;
    }
    DescriptorMatrix d;
    ex.compute_at_angles(*img, fr.circle, angles, d);
    (*mats)[k] = d;
  }
  m.distances = [mats](int k, int l) { return euclidean((*mats)[k], (*mats)[l]); };
  return m;
}

MethodFeatures describe_zncc(const StudySet& set) {
  // Patterns normalised to zero mean and unit norm: ZNCC is then a dot product.
  auto mats = std::make_shared<std::vector<RowMat>>(set.frames.size());
  MethodFeatures m;
  m.name = "zncc";
  for (std::size_t k = 0; k < set.frames.size(); ++k) {
    const auto& fr = set.frames[k];
    PanoramaOptions po;
    po.bearing_sign = set.bearing_sign;
    const Panorama pano = unwrap_panorama(fr.image, fr.circle, po);
    const int w = paper_pattern_columns(pano);
    std::vector<int> ids;
    RowMat a(static_cast<Eigen::Index>(fr.lines.size()),
             static_cast<Eigen::Index>(pano.rows()) * w);
    for (std::size_t i = 0; i < fr.lines.size(); ++i) {
      ids.push_back(fr.lines[i].line_id);
      const cv::Mat1f p = panorama_pattern(pano, fr.lines[i].bearing, w).clone();
      Eigen::Map<const Eigen::VectorXf> v(p.ptr<float>(), static_cast<Eigen::Index>(p.total()));
      Eigen::VectorXf z = v.array() - v.mean();
      const float nrm = z.norm();
      if (nrm > 1e-6f)
        z /= nrm;
      else
        z.setZero();
      a.row(static_cast<Eigen::Index>(i)) = z.transpose();
    }
    m.ids.push_back(ids);
    (*mats)[k] = std::move(a);
  }
  m.distances = [mats](int k, int l) {
    const RowMat& a = (*mats)[k];
    const RowMat& b = (*mats)[l];
    cv::Mat1f out(static_cast<int>(a.rows()), static_cast<int>(b.rows()));
    if (a.rows() == 0 || b.rows() == 0) return out;
    // Patterns of different frames can differ in size when the annulus changes; compare the
    // common top-left part (the simulator and a fixed camera keep them equal).
    const Eigen::Index n = std::min(a.cols(), b.cols());
    const RowMat g = a.leftCols(n) * b.leftCols(n).transpose();
    for (int i = 0; i < out.rows; ++i)
      for (int j = 0; j < out.cols; ++j) out(i, j) = 1.0f - g(i, j);
    return out;
  };
  return m;
}

namespace {

MethodFeatures lbd_from_keylines(std::string name,
                                 std::vector<std::vector<int>> ids,
                                 std::vector<cv::Mat> descs) {
  auto d = std::make_shared<std::vector<cv::Mat>>(std::move(descs));
  MethodFeatures m;
  m.name = std::move(name);
  m.ids = std::move(ids);
  m.distances = [d](int k, int l) {
    const cv::Mat& q = (*d)[k];
    const cv::Mat& t = (*d)[l];
    cv::Mat1f out(q.rows, t.rows, std::numeric_limits<float>::infinity());
    if (q.rows == 0 || t.rows == 0) return out;
    auto matcher = cv::line_descriptor::BinaryDescriptorMatcher::createBinaryDescriptorMatcher();
    std::vector<std::vector<cv::DMatch>> matches;
    matcher->knnMatch(q, t, matches, t.rows);
    for (const auto& row : matches)
      for (const auto& mm : row)
        if (mm.queryIdx >= 0 && mm.queryIdx < q.rows && mm.trainIdx >= 0 && mm.trainIdx < t.rows)
          out(mm.queryIdx, mm.trainIdx) = mm.distance;
    return out;
  };
  return m;
}

}  // namespace

MethodFeatures describe_lbd_segments(const StudySet& set,
                                     const dataset::Dataset& data,
                                     const LbdOptions& o,
                                     double tol) {
  using namespace cv::line_descriptor;
  auto bd = BinaryDescriptor::createBinaryDescriptor();
  auto lsd = LSDDetector::createLSDDetector();
  std::vector<std::vector<int>> ids;
  std::vector<cv::Mat> descs;
  if (!data.ground_truth_error().empty()) throw InputError(data.ground_truth_error());
  if (!data.ground_truth() || !data.ground_truth()->has_lines)
    throw InputError(data.root() + "/ground_truth/lines.csv",
                     0,
                     "file not found: the LBD baseline needs the ground-truth lines");
  const auto& gt = *data.ground_truth();
  for (const auto& fr : set.frames) {
    std::vector<KeyLine> all, kept;
    if (o.use_lsd) {
      lsd->detect(fr.image, all, 2, 1);
    } else {
      bd->detect(fr.image, all);
    }
    const double annulus = fr.circle.r_max - fr.circle.r_min;
    const auto truth = gt.lines_in_frame(fr.index);
    std::vector<int> fid;
    for (const auto& kl : all) {
      if (kl.octave != 0) continue;
      const double mx = 0.5 * (kl.startPointX + kl.endPointX) - fr.circle.center.x();
      const double my = 0.5 * (kl.startPointY + kl.endPointY) - fr.circle.center.y();
      const double r = std::hypot(mx, my);
      const double dx = kl.endPointX - kl.startPointX, dy = kl.endPointY - kl.startPointY;
      const double len = std::hypot(dx, dy);
      if (r < fr.circle.r_min || r > fr.circle.r_max || len < o.min_length_fraction * annulus ||
          r < 1)
        continue;
      const double sin_angle = std::abs(mx * dy - my * dx) / (r * len);
      if (std::asin(std::min(1.0, sin_angle)) > o.max_radial_angle) continue;
      KeyLine k = kl;
      k.class_id = static_cast<int>(kept.size());
      kept.push_back(k);
      const double bearing = wrap_angle(set.bearing_sign * std::atan2(my, mx));
      fid.push_back(associate(bearing, truth, tol));
    }
    cv::Mat desc;
    if (!kept.empty()) bd->compute(fr.image, kept, desc);
    if (desc.rows != static_cast<int>(fid.size())) {
      // compute() may drop lines; keep the ids of the survivors (class_id is the index).
      std::vector<int> f2;
      for (const auto& k : kept) f2.push_back(fid[static_cast<std::size_t>(k.class_id)]);
      fid = f2;
    }
    ids.push_back(fid);
    descs.push_back(desc);
  }
  return lbd_from_keylines(o.use_lsd ? "lbd_lsd" : "lbd_edlines", std::move(ids), std::move(descs));
}

MethodFeatures describe_lbd_on_our_lines(const StudySet& set) {
  using namespace cv::line_descriptor;
  auto bd = BinaryDescriptor::createBinaryDescriptor();
  std::vector<std::vector<int>> ids;
  std::vector<cv::Mat> descs;
  for (const auto& fr : set.frames) {
    std::vector<KeyLine> kls;
    std::vector<int> fid;
    for (std::size_t i = 0; i < fr.lines.size(); ++i) {
      const auto& l = fr.lines[i];
      const double c = std::cos(l.image_angle), s = std::sin(l.image_angle);
      KeyLine k;
      k.startPointX = k.sPointInOctaveX = static_cast<float>(fr.circle.center.x() + l.r_inner * c);
      k.startPointY = k.sPointInOctaveY = static_cast<float>(fr.circle.center.y() + l.r_inner * s);
      k.endPointX = k.ePointInOctaveX = static_cast<float>(fr.circle.center.x() + l.r_outer * c);
      k.endPointY = k.ePointInOctaveY = static_cast<float>(fr.circle.center.y() + l.r_outer * s);
      k.lineLength = static_cast<float>(l.r_outer - l.r_inner);
      k.numOfPixels = static_cast<int>(k.lineLength);
      k.angle =
          static_cast<float>(std::atan2(k.endPointY - k.startPointY, k.endPointX - k.startPointX));
      k.pt = {0.5f * (k.startPointX + k.endPointX), 0.5f * (k.startPointY + k.endPointY)};
      k.octave = 0;
      k.size = k.lineLength;
      k.response = k.lineLength / std::max(fr.image.cols, fr.image.rows);
      k.class_id = static_cast<int>(i);
      kls.push_back(k);
      fid.push_back(l.line_id);
    }
    cv::Mat desc;
    if (!kls.empty()) bd->compute(fr.image, kls, desc);
    if (desc.rows != static_cast<int>(fid.size())) {
      std::vector<int> f2;
      for (const auto& k : kls) f2.push_back(fid[static_cast<std::size_t>(k.class_id)]);
      fid = f2;
    }
    ids.push_back(fid);
    descs.push_back(desc);
  }
  return lbd_from_keylines("lbd_our_lines", std::move(ids), std::move(descs));
}

std::vector<MatchRecord> match_frame_pairs(const StudySet& set, const MethodFeatures& m) {
  std::vector<MatchRecord> out;
  for (std::size_t k = 0; k < set.frames.size(); ++k) {
    const auto& qid = m.ids[k];
    if (std::none_of(qid.begin(), qid.end(), [](int v) { return v >= 0; })) continue;
    for (int l : set.neighbours[k]) {
      const auto& cid = m.ids[static_cast<std::size_t>(l)];
      if (cid.empty()) continue;
      const cv::Mat1f d = m.distances(static_cast<int>(k), l);
      for (int i = 0; i < d.rows; ++i) {
        if (qid[static_cast<std::size_t>(i)] < 0) continue;
        MatchRecord r;
        r.query_frame = static_cast<int>(k);
        r.candidate_frame = l;
        r.query_id = qid[static_cast<std::size_t>(i)];
        r.candidates = d.cols;
        double best = std::numeric_limits<double>::infinity(), second = best, sum = 0;
        int bj = 0;
        for (int j = 0; j < d.cols; ++j) {
          const double v = d(i, j);
          sum += v;
          if (v < best) {
            second = best, best = v, bj = j;
          } else if (v < second) {
            second = v;
          }
          r.has_true |= cid[static_cast<std::size_t>(j)] == r.query_id;
        }
        r.nearest = best, r.second = second, r.mean = sum / d.cols;
        r.nearest_id = cid[static_cast<std::size_t>(bj)];
        out.push_back(r);
      }
    }
  }
  return out;
}

NearestNeighbourScore nearest_neighbour_score(const StudySet& set, const MethodFeatures& m) {
  NearestNeighbourScore s;
  for (std::size_t k = 0; k < set.frames.size(); ++k) {
    const auto& qid = m.ids[k];
    const int n = static_cast<int>(qid.size());
    std::vector<double> best(n, std::numeric_limits<double>::infinity());
    std::vector<int> best_id(n, -2);
    std::vector<char> present(n, 0);
    for (int l : set.neighbours[k]) {
      const auto& cid = m.ids[static_cast<std::size_t>(l)];
      if (cid.empty()) continue;
      const cv::Mat1f d = m.distances(static_cast<int>(k), l);
      for (int i = 0; i < d.rows && i < n; ++i) {
        if (qid[i] < 0) continue;
        for (int j = 0; j < d.cols; ++j) {
          if (cid[j] == qid[i]) present[i] = 1;
          if (d(i, j) < best[i]) best[i] = d(i, j), best_id[i] = cid[j];
        }
      }
    }
    for (int i = 0; i < n; ++i) {
      if (qid[i] < 0 || !present[i]) continue;
      ++s.queries;
      s.correct += best_id[i] == qid[i];
    }
  }
  return s;
}

NearestNeighbourScore pair_nearest_score(const StudySet& set,
                                         const std::vector<MatchRecord>& records,
                                         double min_baseline,
                                         double max_baseline) {
  NearestNeighbourScore s;
  for (const auto& r : records) {
    if (!r.has_true) continue;
    const auto& a = set.frames[static_cast<std::size_t>(r.query_frame)];
    const auto& b = set.frames[static_cast<std::size_t>(r.candidate_frame)];
    const double d = std::hypot(a.x - b.x, a.y - b.y);
    if (d < min_baseline || d > max_baseline) continue;
    ++s.queries;
    s.correct += r.correct();
  }
  return s;
}

double rule_value(const MatchRecord& r, int rule) {
  switch (rule) {
    case 1:
      return r.nearest;
    case 2:
      return r.mean > 0 ? r.nearest / r.mean : 1.0;
    default:
      if (r.candidates < 2 || !std::isfinite(r.second)) return 0.0;  // vacuous (matcher.cpp)
      return r.second > 0 ? r.nearest / r.second : 1.0;
  }
}

RuleShares rule_shares(const std::vector<MatchRecord>& records, int rule, double t) {
  RuleShares s;
  s.threshold = t;
  std::int64_t fr = 0, cl = 0;
  for (const auto& r : records) {
    const bool reject = !(rule_value(r, rule) <= t);
    if (r.correct()) {
      ++s.correct, cl += reject;
    } else {
      ++s.incorrect, fr += reject;
    }
  }
  s.false_removed = s.incorrect > 0 ? static_cast<double>(fr) / s.incorrect : 0.0;
  s.correct_lost = s.correct > 0 ? static_cast<double>(cl) / s.correct : 0.0;
  return s;
}

std::vector<PrPoint> precision_recall(const std::vector<MatchRecord>& records, int max_points) {
  std::vector<std::pair<double, bool>> v;
  std::int64_t positives = 0;
  for (const auto& r : records) {
    v.push_back({rule_value(r, 3), r.correct()});
    positives += r.has_true;
  }
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<PrPoint> full;
  std::int64_t acc = 0, cor = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    ++acc, cor += v[i].second;
    if (i + 1 < v.size() && v[i + 1].first == v[i].first) continue;  // ties: one point
    full.push_back({v[i].first,
                    static_cast<double>(cor) / acc,
                    positives > 0 ? static_cast<double>(cor) / positives : 0.0});
  }
  if (max_points <= 0 || static_cast<int>(full.size()) <= max_points) return full;
  std::vector<PrPoint> out;
  for (int i = 0; i < max_points; ++i)
    out.push_back(full[static_cast<std::size_t>(
        std::lround(static_cast<double>(i) * (full.size() - 1) / (max_points - 1)))]);
  return out;
}

double precision_at_recall(const std::vector<PrPoint>& curve, double r) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const auto& p : curve)
    if (p.recall >= r && !(p.precision <= best)) best = p.precision;
  return best;
}

double average_precision(const std::vector<PrPoint>& curve) {
  double ap = 0, prev_r = 0;
  for (const auto& p : curve) {
    ap += (p.recall - prev_r) * p.precision;
    prev_r = p.recall;
  }
  return ap;
}

PrPoint rules_operating_point(const std::vector<MatchRecord>& records,
                              double f1,
                              double f2,
                              double f3) {
  std::int64_t acc = 0, cor = 0, pos = 0;
  for (const auto& r : records) {
    pos += r.has_true;
    if (rule_value(r, 1) <= f1 && rule_value(r, 2) <= f2 && rule_value(r, 3) <= f3)
      ++acc, cor += r.correct();
  }
  PrPoint p;
  p.precision = acc > 0 ? static_cast<double>(cor) / acc : 0.0;
  p.recall = pos > 0 ? static_cast<double>(cor) / pos : 0.0;
  return p;
}

}  // namespace omnivert::eval
