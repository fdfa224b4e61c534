// The descriptor of Sec. 3 on constructed inputs with known answers.

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/describe/descriptor.hpp"

namespace omnivert {
namespace {

MirrorCircle circle_at(double cx, double cy) {
  MirrorCircle c;
  c.center = {cx, cy};
  c.r_min = 40;
  c.r_max = 220;
  c.rim_radius = 228;
  return c;
}

TEST(Descriptor, SizeIs192ForThePaperSettings) {
  DescriptorOptions o;
  EXPECT_EQ(o.size(), kPaperDescriptorSize);
  o.areas = 5;
  o.bins = 8;
  EXPECT_EQ(o.size(), 5 * 2 * 8);
  std::string why;
  o.areas = 4;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("areas"), std::string::npos);
}

TEST(Descriptor, UnitsAreUnitLengthAndClippedBeforeRenormalising) {
  // A half-plane edge through the centre along image angle 0: bright below (v > cy).
  cv::Mat img(480, 640, CV_8U, cv::Scalar(60));
  img(cv::Rect(0, 240, 640, 240)).setTo(180);
  cv::GaussianBlur(img, img, cv::Size(), 1.0);
  for (auto norm : {DescriptorNormalization::kPerPair, DescriptorNormalization::kPerHalf}) {
    DescriptorOptions o;
    o.normalization = norm;
    DescriptorExtractor d(o);
    DescriptorMatrix m;
    const double angles[] = {0.0};
    d.compute_at_angles(img, circle_at(320, 239.5), angles, m);
    ASSERT_EQ(m.cols(), 192);
    const int unit = norm == DescriptorNormalization::kPerPair ? 64 : 32;
    for (int s = 0; s < 192; s += unit) {
      const float n = m.row(0).segment(s, unit).norm();
      if (n > 0) {
        EXPECT_NEAR(n, 1.0, 1e-5);
      }
      EXPECT_TRUE(m.row(0).segment(s, unit).allFinite());
    }
  }
}

TEST(Descriptor, EdgeGradientFallsInTheBinOfItsRelativeOrientation) {
  // Edge along image angle 0 (the +u axis), brighter at larger v: the gradient points to +v,
  // i.e. at +90 degrees from the line. Relative orientation pi/2 -> bin 8 of 32 (eq. 2), and
  // with no other structure the votes are there and in its soft neighbours only.
  cv::Mat img(480, 640, CV_8U, cv::Scalar(60));
  img(cv::Rect(0, 240, 640, 240)).setTo(180);
  DescriptorOptions o;
  o.clip = 1.0;  // no clipping: see the raw shape
  DescriptorExtractor d(o);
  DescriptorMatrix m;
  const double angles[] = {0.0};
  d.compute_at_angles(img, circle_at(320, 239.5), angles, m);
  for (int h = 0; h < 6; ++h) {
    const auto hist = m.row(0).segment(h * 32, 32);
    Eigen::Index arg;
    hist.maxCoeff(&arg);
    EXPECT_EQ(arg, 8) << "histogram " << h;
    double outside = 0;
    for (int b = 0; b < 32; ++b)
      if (b < 7 || b > 9) outside += hist(b);
    EXPECT_LT(outside, 1e-3) << "histogram " << h;
  }
}

TEST(Descriptor, RotatingTheImageBy90DegreesLeavesItUnchanged) {
  // A grid-exact rotation: the descriptor at the rotated angle must be the same vector.
  cv::Mat img(481, 641, CV_8U);
  cv::randu(img, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(), 3.0);
  cv::Mat rot;
  cv::rotate(img(cv::Rect(80, 0, 481, 481)), rot, cv::ROTATE_90_CLOCKWISE);  // a -> a + 90 deg
  const MirrorCircle c = circle_at(240, 240);
  DescriptorOptions full;
  full.min_samples_per_sigma = 1e9;  // the plain full-resolution reference
  DescriptorExtractor d(full);
  DescriptorMatrix m0, m1;
  for (double a_deg : {10.0, 77.0, -140.0}) {
    const double a0[] = {deg2rad(a_deg)};
    const double a1[] = {deg2rad(a_deg + 90.0)};
    d.compute_at_angles(img(cv::Rect(80, 0, 481, 481)).clone(), c, a0, m0);
    d.compute_at_angles(rot, c, a1, m1);
    EXPECT_LT((m0 - m1).norm(), 0.02) << a_deg;
  }
}

TEST(Descriptor, SampledFastPathStaysCloseToTheFullResolutionReference) {
  // The blur reading samples the blurred gradients every floor(sigma_G / 5) pixels; on a
  // textured image it must agree with the full-resolution computation.
  cv::Mat img(480, 640, CV_8U);
  cv::randu(img, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(), 3.0);
  const MirrorCircle c = circle_at(320, 240);
  DescriptorOptions full;
  full.min_samples_per_sigma = 1e9;
  DescriptorExtractor fast, ref(full);
  std::vector<double> angles;
  for (int k = 0; k < 36; ++k) angles.push_back(deg2rad(10.0 * k + 3.7));
  DescriptorMatrix a, b;
  fast.compute_at_angles(img, c, angles, a);
  ref.compute_at_angles(img, c, angles, b);
  double worst = 0;
  for (int i = 0; i < a.rows(); ++i)
    worst = std::max(worst, static_cast<double>((a.row(i) - b.row(i)).norm()));
  EXPECT_LT(worst, 0.1);
}

TEST(Descriptor, FastPathEqualsThePlainReference) {
  // The fast path (magnitude and orientation tabled once per frame, rows cut to the disc)
  // against the plain per-sample computation: the same bits, for both smoothings, both
  // normalisation units, five areas, a mask, and angles all around (negative, past 2 pi);
  // a centred mirror and one whose annulus leaves the frame (the table covers the annulus
  // only, cut to the frame).
  cv::Mat img(480, 640, CV_8U);
  cv::randu(img, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(), 1.5);
  cv::Mat usable(img.size(), CV_8U, cv::Scalar(255));
  cv::line(usable, {320, 240}, {560, 90}, cv::Scalar(0), 9);
  cv::circle(usable, {250, 330}, 40, cv::Scalar(0), cv::FILLED);
  std::vector<double> angles;
  for (int k = 0; k < 40; ++k) angles.push_back(deg2rad(-190.0 + 13.7 * k));
  int compared = 0;
  for (const MirrorCircle& c : {circle_at(321.3, 238.6), circle_at(203.7, 301.2)})
    for (auto smoothing :
         {DescriptorSmoothing::kGaussianBlur, DescriptorSmoothing::kGaussianWeight})
      for (auto norm : {DescriptorNormalization::kPerPair, DescriptorNormalization::kPerHalf})
        for (int areas : {3, 5})
          for (bool masked : {false, true}) {
            DescriptorOptions o;
            o.smoothing = smoothing;
            o.normalization = norm;
            o.areas = areas;
            DescriptorOptions plain = o;
            plain.reference = true;
            DescriptorExtractor fast(o), ref(plain);
            if (masked) {
              fast.set_mask(usable);
              ref.set_mask(usable);
            }
            DescriptorMatrix a, b;
            fast.compute_at_angles(img, c, angles, a);
            ref.compute_at_angles(img, c, angles, b);
            ASSERT_EQ(a.rows(), b.rows());
            ASSERT_GT(b.norm(), 0.0f);
            EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0f)
                << "smoothing " << static_cast<int>(smoothing) << " unit " << static_cast<int>(norm)
                << " areas " << areas << " masked " << masked;
            ++compared;
          }
  EXPECT_EQ(compared, 32);
}

TEST(Descriptor, FlatImageGivesZerosNotNaN) {
  cv::Mat img(480, 640, CV_8U, cv::Scalar(128));
  DescriptorExtractor d;
  DescriptorMatrix m;
  const double angles[] = {0.3, 2.0};
  d.compute_at_angles(img, circle_at(320, 240), angles, m);
  EXPECT_TRUE(m.allFinite());
  EXPECT_EQ(m.norm(), 0.0f);
}

TEST(Descriptor, LeftAndRightHalvesSwapWhenTheSidesSwap) {
  // Two images mirrored across the line: the left half of one is the right half of the other
  // with the relative orientation mirrored (phi -> -phi).
  cv::Mat img(480, 640, CV_8U);
  cv::randu(img, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(), 4.0);
  cv::Mat flipped;
  cv::flip(img, flipped, 0);  // v -> 479 - v: mirror across the horizontal line v = 239.5
  const MirrorCircle c = circle_at(320, 239.5);
  DescriptorOptions o;
  o.clip = 1.0;
  DescriptorExtractor d(o);
  DescriptorMatrix m0, m1;
  const double a[] = {0.0};
  d.compute_at_angles(img, c, a, m0);
  d.compute_at_angles(flipped, c, a, m1);
  for (int k = 0; k < 3; ++k) {
    const auto l0 = m0.row(0).segment((2 * k) * 32, 32);
    const auto r1 = m1.row(0).segment((2 * k + 1) * 32, 32);
    // Mirrored orientation: bin position t -> 32 - t, so bin b of one is bin (32 - b) % 32 of
    // the other.
    double err = 0;
    for (int b = 0; b < 32; ++b) err += std::abs(l0(b) - r1((32 - b) % 32));
    EXPECT_LT(err, 0.05) << "area " << k;
  }
}

}  // namespace
}  // namespace omnivert
