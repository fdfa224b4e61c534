// to_grey8: colour, 16-bit and Bayer images read from files written by libpng and libjpeg
// (through OpenCV's writers) come out as the grey a user expects.

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "omnivert/image/grey.hpp"
#include "omnivert/image/image_io.hpp"

namespace omnivert {
namespace {

namespace fs = std::filesystem;

// ITU-R BT.601 luma of an 8-bit colour.
double luma(double r, double g, double b) { return 0.299 * r + 0.587 * g + 0.114 * b; }

class GreyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("omnivert_grey_" + std::to_string(::getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  // Writes `m` to a file (the extension picks the writer) and reads it back as stored.
  cv::Mat round_trip(const cv::Mat& m, const std::string& name, std::vector<int> params = {}) {
    const std::string path = (dir / name).string();
    EXPECT_TRUE(cv::imwrite(path, m, params));
    return read_image(path);
  }
  cv::Mat grey(const cv::Mat& m, PixelFormat f = {}) {
    cv::Mat g;
    std::string why;
    EXPECT_TRUE(to_grey8(m, f, g, &why)) << why;
    EXPECT_EQ(g.type(), CV_8UC1);
    return g;
  }
  fs::path dir;
};

// Four 32x32 blocks of known colours (BGR order, as OpenCV stores colour).
cv::Mat colour_blocks(int depth_scale, int type) {
  cv::Mat m(32, 128, type);
  const cv::Vec3d bgr[4] = {{0, 0, 255}, {0, 255, 0}, {255, 0, 0}, {40, 120, 200}};
  for (int k = 0; k < 4; ++k) {
    m(cv::Rect(32 * k, 0, 32, 32))
        .setTo(
            cv::Scalar(bgr[k][0] * depth_scale, bgr[k][1] * depth_scale, bgr[k][2] * depth_scale));
  }
  return m;
}

void expect_block_lumas(const cv::Mat1b& g, double tolerance) {
  const double expected[4] = {
      luma(255, 0, 0), luma(0, 255, 0), luma(0, 0, 255), luma(200, 120, 40)};
  for (int k = 0; k < 4; ++k) {
    // The block's interior: JPEG blurs colour across block borders.
    const double v = cv::mean(g(cv::Rect(32 * k + 8, 8, 16, 16)))[0];
    EXPECT_NEAR(v, expected[k], tolerance) << "block " << k;
  }
}

TEST_F(GreyTest, ColourPngIsLuma) {
  const cv::Mat read = round_trip(colour_blocks(1, CV_8UC3), "c.png");
  ASSERT_EQ(read.channels(), 3);
  expect_block_lumas(grey(read), 0.51);
}

TEST_F(GreyTest, ColourPngWithAlphaIsLuma) {
  cv::Mat bgra;
  cv::Mat planes[4];
  cv::split(colour_blocks(1, CV_8UC3), planes);
  planes[3] = cv::Mat(32, 128, CV_8UC1, cv::Scalar(255));
  cv::merge(planes, 4, bgra);
  const cv::Mat read = round_trip(bgra, "ca.png");
  ASSERT_EQ(read.channels(), 4);
  expect_block_lumas(grey(read), 0.51);
}

TEST_F(GreyTest, ColourJpegIsLuma) {
  const cv::Mat read =
      round_trip(colour_blocks(1, CV_8UC3), "c.jpg", {cv::IMWRITE_JPEG_QUALITY, 95});
  ASSERT_EQ(read.channels(), 3);
  expect_block_lumas(grey(read), 2.0);  // lossy: the decoder's colour conversion and rounding
}

TEST_F(GreyTest, SixteenBitColourPngIsLumaOfTheFullRange) {
  const cv::Mat read = round_trip(colour_blocks(257, CV_16UC3), "c16.png");
  ASSERT_EQ(read.depth(), CV_16U);
  expect_block_lumas(grey(read), 0.51);
}

TEST_F(GreyTest, SixteenBitGreyPngUsesTheFullRangeByDefault) {
  cv::Mat1w m(1, 256);
  for (int v = 0; v < 256; ++v) m(0, v) = static_cast<uint16_t>(v * 257);
  const cv::Mat1b g = grey(round_trip(m, "g16.png"));
  for (int v = 0; v < 256; ++v) ASSERT_EQ(g(0, v), v);
}

TEST_F(GreyTest, TwelveBitValuesAreScaledByTheBitDepth) {
  cv::Mat1w m(1, 4096);
  for (int v = 0; v < 4096; ++v) m(0, v) = static_cast<uint16_t>(v);
  const cv::Mat read = round_trip(m, "g12.png");
  PixelFormat twelve;
  twelve.bit_depth = 12;
  const cv::Mat1b g = grey(read, twelve);
  for (int v = 0; v < 4096; ++v) ASSERT_EQ(g(0, v), std::lround(v * 255.0 / 4095.0)) << v;
  // Read as full-range 16 bits the same file is 16 times darker: the reason for bit_depth.
  EXPECT_EQ(cv::Mat1b(grey(read))(0, 4095), 16);
}

TEST_F(GreyTest, FloatImagesInZeroToOne) {
  cv::Mat1f m(1, 3);
  m << 0.0f, 0.5f, 1.0f;
  const cv::Mat1b g = grey(m);
  EXPECT_EQ(g(0, 0), 0);
  EXPECT_EQ(g(0, 1), 128);
  EXPECT_EQ(g(0, 2), 255);
}

// A colour image sampled through a colour filter array `pattern` (the colours of the top-left
// 2x2 block row by row): what a raw camera stores.
template <typename T>
cv::Mat mosaic(const cv::Mat& bgr, const std::string& pattern) {
  cv::Mat out(bgr.rows, bgr.cols, cv::DataType<T>::type);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const char c = pattern[2 * (y % 2) + (x % 2)];
      const int ch = c == 'B' ? 0 : c == 'G' ? 1 : 2;
      out.at<T>(y, x) = bgr.at<cv::Vec<T, 3>>(y, x)[ch];
    }
  }
  return out;
}

// Left half pure red, right half pure blue: a swapped pattern turns red into blue.
cv::Mat red_blue(int scale, int type) {
  cv::Mat m(32, 64, type);
  m(cv::Rect(0, 0, 32, 32)).setTo(cv::Scalar(0, 0, 255 * scale));
  m(cv::Rect(32, 0, 32, 32)).setTo(cv::Scalar(255 * scale, 0, 0));
  return m;
}

TEST_F(GreyTest, EveryBayerPatternDemosaicsToTheGreyOfTheScene) {
  const std::pair<std::string, BayerPattern> patterns[] = {{"RGGB", BayerPattern::kRGGB},
                                                           {"BGGR", BayerPattern::kBGGR},
                                                           {"GRBG", BayerPattern::kGRBG},
                                                           {"GBRG", BayerPattern::kGBRG}};
  const cv::Mat scene = red_blue(1, CV_8UC3);
  for (const auto& [name, p] : patterns) {
    const cv::Mat raw = round_trip(mosaic<uint8_t>(scene, name), "raw_" + name + ".png");
    ASSERT_EQ(raw.channels(), 1);
    PixelFormat f;
    f.bayer = p;
    const cv::Mat1b g = grey(raw, f);
    const double red = cv::mean(g(cv::Rect(8, 8, 16, 16)))[0];
    const double blue = cv::mean(g(cv::Rect(40, 8, 16, 16)))[0];
    EXPECT_NEAR(red, luma(255, 0, 0), 1.0) << name;
    EXPECT_NEAR(blue, luma(0, 0, 255), 1.0) << name;
  }
  // The pattern matters: RGGB read as BGGR swaps red and blue.
  PixelFormat wrong;
  wrong.bayer = BayerPattern::kBGGR;
  const cv::Mat1b g = grey(mosaic<uint8_t>(scene, "RGGB"), wrong);
  EXPECT_NEAR(cv::mean(g(cv::Rect(8, 8, 16, 16)))[0], luma(0, 0, 255), 1.0);
}

TEST_F(GreyTest, SixteenBitBayer) {
  const cv::Mat raw = round_trip(mosaic<uint16_t>(red_blue(257, CV_16UC3), "GRBG"), "raw16.png");
  ASSERT_EQ(raw.depth(), CV_16U);
  PixelFormat f;
  f.bayer = BayerPattern::kGRBG;
  const cv::Mat1b g = grey(raw, f);
  EXPECT_NEAR(cv::mean(g(cv::Rect(8, 8, 16, 16)))[0], luma(255, 0, 0), 1.0);
  EXPECT_NEAR(cv::mean(g(cv::Rect(40, 8, 16, 16)))[0], luma(0, 0, 255), 1.0);
}

std::string refusal(const cv::Mat& m, PixelFormat f = {}) {
  cv::Mat g;
  std::string why;
  EXPECT_FALSE(to_grey8(m, f, g, &why));
  return why;
}

TEST_F(GreyTest, WhatCannotBeConvertedIsRefusedWithAReason) {
  EXPECT_EQ(refusal(cv::Mat(4, 4, CV_8UC2)),
            "an image with 2 channels (expected grey, colour or colour with alpha)");
  EXPECT_EQ(refusal(cv::Mat(4, 4, CV_16SC1)),
            "16-bit signed pixels are not supported (expected 8- or 16-bit unsigned, or "
            "floating point in 0..1)");
  PixelFormat bayer;
  bayer.bayer = BayerPattern::kRGGB;
  EXPECT_EQ(refusal(cv::Mat(4, 4, CV_8UC3), bayer),
            "the camera's images are Bayer mosaics (bayer: RGGB) but this image has 3 channels; "
            "set bayer: none in sensor.yaml for colour images");
  PixelFormat twelve;
  twelve.bit_depth = 12;
  EXPECT_EQ(refusal(cv::Mat(4, 4, CV_8UC1), twelve),
            "the camera's bit_depth is 12 but the image is not 16 bits deep; remove bit_depth "
            "from sensor.yaml");
  EXPECT_EQ(refusal(cv::Mat()), "empty image");
}

TEST(BayerPatternNames, ParseAndPrint) {
  for (const char* n : {"RGGB", "BGGR", "GRBG", "GBRG", "none"}) {
    const auto p = parse_bayer_pattern(n);
    ASSERT_TRUE(p) << n;
    EXPECT_STREQ(bayer_pattern_name(*p), n);
  }
  EXPECT_EQ(parse_bayer_pattern("rggb"), BayerPattern::kRGGB);
  EXPECT_FALSE(parse_bayer_pattern("RGBG"));
}

}  // namespace
}  // namespace omnivert
