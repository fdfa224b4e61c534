#include "omnivert/eval/real_image_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <sstream>
#include <utility>

#include "omnivert/core/angles.hpp"
#include "omnivert/eval/invariance.hpp"

namespace omnivert::eval {

bool RealImageStudyOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!pipeline.IsValid(why)) return false;
  if (strongest < 1) return fail("strongest must be at least 1");
  if (!(tolerance_deg > 0 && tolerance_deg < 10)) return fail("tolerance_deg must be in (0, 10)");
  for (const Lighting& l : lightings)
    if (!(l.gain > 0 && l.gamma > 0)) return fail("gain and gamma must be positive");
  return true;
}

RepeatCount& RepeatCount::operator+=(const RepeatCount& o) {
  looked_for += o.looked_for;
  found += o.found;
  nn_correct += o.nn_correct;
  nn_correct_polarity += o.nn_correct_polarity;
  return *this;
}

namespace {

bool features_of(const cv::Mat& image,
                 const CameraGeometry& geometry,
                 const FeaturePipelineOptions& options,
                 FrameFeatures* f,
                 std::string* why,
                 const std::optional<std::pair<Eigen::Vector2d, double>>& rotation = {}) {
  FeaturePipeline pipe(geometry, options);
  // A rotated copy (centre, angle): its mask is the camera's, rotated, less the corners the
  // rotation filled with zeros.
  if (rotation)
    pipe.set_mask(rotated_usable(pipe.mask(), image.size(), rotation->first, rotation->second));
  return pipe.process(image, *f, why);
}

// The `n` most significant lines of f (indices).
std::vector<int> strongest_lines(const FrameFeatures& f, int n) {
  std::vector<int> idx(f.lines.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) {
    return f.lines[a].significance > f.lines[b].significance;
  });
  if (static_cast<int>(idx.size()) > n) idx.resize(n);
  return idx;
}

// Looks for the lines `which` of `a` in `b` at image angle + shift (same polarity, nearest
// within tol), and checks that the nearest descriptor of b's lines to each is the one found.
RepeatCount repeat(const FrameFeatures& a,
                   const std::vector<int>& which,
                   const FrameFeatures& b,
                   double shift,
                   double tol) {
  RepeatCount c;
  c.looked_for = static_cast<int>(which.size());
  // Found again: pair_lines' match at the shifted image angle (same polarity, within tol).
  for (const LinePairing& p : pair_lines(a, b, shift, tol)) {
    if (std::find(which.begin(), which.end(), p.original) == which.end()) continue;
    ++c.found;
    // Right descriptor: the original line's nearest among all of the copy's lines is its match.
    // The same among the copy's lines of the line's polarity.
    int nn = -1, nn_pol = -1;
    double nn_d = 0, nn_pol_d = 0;
    const int polarity = a.lines[p.original].polarity;
    for (int j = 0; j < static_cast<int>(b.lines.size()); ++j) {
      const double d = (a.descriptors.row(p.original) - b.descriptors.row(j)).norm();
      if (nn < 0 || d < nn_d) nn = j, nn_d = d;
      if (b.lines[j].polarity == polarity && (nn_pol < 0 || d < nn_pol_d)) nn_pol = j, nn_pol_d = d;
    }
    if (nn == p.transformed) ++c.nn_correct;
    if (nn_pol == p.transformed) ++c.nn_correct_polarity;
  }
  return c;
}

}  // namespace

RealImageResult study_real_image(const std::string& label,
                                 const cv::Mat& image,
                                 const CameraGeometry& geometry,
                                 const RealImageStudyOptions& o) {
  RealImageResult r;
  r.label = label;
  r.width = image.cols, r.height = image.rows;
  CameraGeometry user = geometry;
  user.width = image.cols, user.height = image.rows;
  FrameFeatures f0;
  if (!features_of(image, user, o.pipeline, &f0, &r.error)) return r;
  r.ok = true;
  r.circle = f0.circle;
  r.lines = static_cast<int>(f0.lines.size());
  const std::vector<int> top = strongest_lines(f0, o.strongest);
  CameraGeometry given = user;
  given.center = f0.circle.center;
  given.r_min = f0.circle.r_min;
  given.r_max = f0.circle.r_max;
  const double tol = deg2rad(o.tolerance_deg);
  for (int mode = 0; mode < 2; ++mode) {
    const CameraGeometry& g = mode == 0 ? user : given;
    for (double deg : o.rotations_deg) {
      const double t = deg2rad(deg);
      FrameFeatures f1;
      std::string why;
      const cv::Mat rotated = rotate_about(image, f0.circle.center, t);
      if (!features_of(rotated, g, o.pipeline, &f1, &why, std::pair(f0.circle.center, t))) {
        r.rotation[mode].looked_for += static_cast<int>(top.size());
        continue;
      }
      if (mode == 0)
        r.max_centre_shift_px =
            std::max(r.max_centre_shift_px, (f1.circle.center - f0.circle.center).norm());
      r.rotation[mode] += repeat(f0, top, f1, t, tol);
    }
    for (const auto& l : o.lightings) {
      FrameFeatures f1;
      std::string why;
      if (!features_of(relight(image, l.gain, l.gamma), g, o.pipeline, &f1, &why)) {
        r.lighting[mode].looked_for += static_cast<int>(top.size());
        continue;
      }
      r.lighting[mode] += repeat(f0, top, f1, 0.0, tol);
    }
  }
  return r;
}

namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

std::string real_image_table(const std::vector<RealImageResult>& results) {
  std::ostringstream s;
  char b[256];
  std::snprintf(b,
                sizeof b,
                "%-32s %16s %6s | %-21s | %-21s | %-21s | %-21s\n",
                "",
                "",
                "",
                "rotation, detected",
                "rotation, given",
                "lighting, detected",
                "lighting, given");
  s << b;
  std::snprintf(b,
                sizeof b,
                "%-32s %16s %6s |%s|%s|%s|%s\n",
                "image",
                "centre [px]",
                "lines",
                " found %  NN %  shift ",
                " found %  NN %        ",
                " found %  NN %        ",
                " found %  NN %        ");
  s << b;
  RepeatCount tr[2], tl[2];
  int images = 0, lines = 0;
  for (const RealImageResult& r : results) {
    if (!r.ok) {
      s << r.label << ": " << r.error << '\n';
      continue;
    }
    ++images;
    lines += r.lines;
    for (int m = 0; m < 2; ++m) tr[m] += r.rotation[m], tl[m] += r.lighting[m];
    std::snprintf(
        b,
        sizeof b,
        "%-32s (%6.1f, %6.1f) %6d | %6.1f %5.1f %6.2f | %6.1f %5.1f        | %6.1f %5.1f  "
        "      | %6.1f %5.1f\n",
        r.label.c_str(),
        r.circle.center.x(),
        r.circle.center.y(),
        r.lines,
        r.rotation[0].found_percent(),
        r.rotation[0].nn_percent(),
        r.max_centre_shift_px,
        r.rotation[1].found_percent(),
        r.rotation[1].nn_percent(),
        r.lighting[0].found_percent(),
        r.lighting[0].nn_percent(),
        r.lighting[1].found_percent(),
        r.lighting[1].nn_percent());
    s << b;
  }
  std::snprintf(b,
                sizeof b,
                "%-32s %16s %6s | %6.1f %5.1f        | %6.1f %5.1f        | %6.1f %5.1f        | "
                "%6.1f %5.1f\n",
                ("all (" + std::to_string(images) + " images)").c_str(),
                "",
                fmt("%.1f", images ? static_cast<double>(lines) / images : 0.0).c_str(),
                tr[0].found_percent(),
                tr[0].nn_percent(),
                tr[1].found_percent(),
                tr[1].nn_percent(),
                tl[0].found_percent(),
                tl[0].nn_percent(),
                tl[1].found_percent(),
                tl[1].nn_percent());
  s << b;
  std::snprintf(b,
                sizeof b,
                "NN among the copy's lines of the same polarity: rotation %.1f / %.1f %%, lighting "
                "%.1f / %.1f %% (detected / given)\n",
                tr[0].nn_polarity_percent(),
                tr[1].nn_polarity_percent(),
                tl[0].nn_polarity_percent(),
                tl[1].nn_polarity_percent());
  s << b;
  return s.str();
}

std::string real_image_csv(const std::vector<RealImageResult>& results) {
  std::ostringstream s;
  s << "#image,ok,width,height,center_x,center_y,r_min,r_max,lines,max_centre_shift_px";
  for (const char* t :
       {"rotation_detected", "rotation_given", "lighting_detected", "lighting_given"})
    s << ',' << t << "_looked_for," << t << "_found," << t << "_nn_correct," << t
      << "_nn_correct_same_polarity";
  s << '\n';
  for (const RealImageResult& r : results) {
    s << r.label << ',' << (r.ok ? 1 : 0) << ',' << r.width << ',' << r.height << ','
      << fmt("%.3f", r.circle.center.x()) << ',' << fmt("%.3f", r.circle.center.y()) << ','
      << fmt("%.2f", r.circle.r_min) << ',' << fmt("%.2f", r.circle.r_max) << ',' << r.lines << ','
      << fmt("%.3f", r.max_centre_shift_px);
    for (const RepeatCount* c : {&r.rotation[0], &r.rotation[1], &r.lighting[0], &r.lighting[1]})
      s << ',' << c->looked_for << ',' << c->found << ',' << c->nn_correct << ','
        << c->nn_correct_polarity;
    s << '\n';
  }
  return s.str();
}

}  // namespace omnivert::eval
