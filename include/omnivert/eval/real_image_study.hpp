#pragma once
// The real-image study (docs/validation.md#real-images): on real catadioptric images, which
// have no ground truth, what a picture itself gives. Each image is rotated about its detected
// mirror centre (a pure rotation of the camera, Sec. 3.1) and re-lit (gain, gamma: Sec. 3.3),
// features are extracted again at the given options, and the strongest lines of the original
// (by significance) are looked for at their shifted image angle; for each one found, is the
// nearest descriptor of the transformed image's lines its own? Measured twice: with the
// centre and annulus detected again on the transformed image (what a user gets) and with the
// original's circle given.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/describe/feature_pipeline.hpp"

namespace omnivert::eval {

struct RealImageStudyOptions {
  FeaturePipelineOptions pipeline;
  // Rotations about the mirror centre, degrees (not multiples of 90: no exact pixel shuffle).
  std::vector<double> rotations_deg{7, 23, 41, 137};
  struct Lighting {
    double gain = 1, gamma = 1;  // out = 255 (gain in / 255)^gamma (eval/invariance.hpp)
  };
  std::vector<Lighting> lightings{{0.6, 1}, {0.8, 1}, {1.2, 1}, {1, 0.7}, {1, 1.4}};
  int strongest = 25;          // lines of the original looked for, the most significant
  double tolerance_deg = 0.3;  // found again: same polarity, image angle within this

  bool IsValid(std::string* why) const;
};

// Counts over one or more transformed copies.
struct RepeatCount {
  int looked_for = 0;  // strongest lines of the original, once per copy
  int found = 0;       // found again at the shifted image angle
  int nn_correct = 0;  // of those found: the nearest descriptor in the copy is the right line
  // Of those found: the nearest descriptor among the copy's lines of the same edge polarity
  // is the right line (the tracker's recommended rules compare only those).
  int nn_correct_polarity = 0;
  double found_percent() const { return looked_for ? 100.0 * found / looked_for : 0.0; }
  double nn_percent() const { return found ? 100.0 * nn_correct / found : 0.0; }
  double nn_polarity_percent() const { return found ? 100.0 * nn_correct_polarity / found : 0.0; }
  RepeatCount& operator+=(const RepeatCount& o);
};

struct RealImageResult {
  std::string label;
  int width = 0, height = 0;
  bool ok = false;    // false: the mirror was not found (`error` says why)
  std::string error;  // the pipeline's reason
  MirrorCircle circle;
  int lines = 0;
  // [0]: circle detected on each copy; [1]: the original's circle given.
  RepeatCount rotation[2], lighting[2];
  double max_centre_shift_px = 0;  // detected centre of a rotated copy vs the rotation centre
};

// Runs the study on one image with the camera geometry a user would give (empty: detected).
RealImageResult study_real_image(const std::string& label,
                                 const cv::Mat& image,
                                 const CameraGeometry& geometry,
                                 const RealImageStudyOptions& options);

// The table of results, one row per image and a total row, as text (for printing) and CSV.
std::string real_image_table(const std::vector<RealImageResult>& results);
std::string real_image_csv(const std::vector<RealImageResult>& results);

}  // namespace omnivert::eval
