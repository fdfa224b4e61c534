#include "omnivert/match/tracks_io.hpp"
#include "omnivert/viz/tracks_plot.hpp"

#include <unistd.h>
#include <cmath>

#include <cstdlib>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert {
namespace {

namespace fs = std::filesystem;

// A scratch directory of one test, removed when the test ends (pid: ctest runs tests in
// parallel processes).
class ScratchDir {
 public:
  ScratchDir()
      : path_(fs::temp_directory_path() /
              ("omnivert_tracks_io_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write_text(const fs::path& p, const std::string& s) {
  std::ofstream f(p);
  f << s;
}

TEST(TracksCsv, RoundTrip) {
  FrameFeatures frame;
  for (int i = 0; i < 3; ++i) {
    VerticalLine v;
    v.bearing = wrap_angle(3.0 + i * 0.1);
    v.image_angle = -v.bearing;
    v.edge_pixels = 100 + i;
    v.r_inner = 40.5;
    v.r_outer = 180.25;
    v.crowded = i == 1;
    v.annulus_fraction = 0.25 * (i + 1);
    frame.lines.push_back(v);
  }
  std::vector<TrackAssignment> as(3);
  as[0].track_id = 7;
  as[0].frames_back = 1;
  as[0].distance = 0.25f;
  as[1].track_id = 9;  // new
  as[2].track_id = 2;
  as[2].frames_back = 5;
  as[2].matched_line = 4;
  std::vector<TrackRow> rows;
  append_track_rows(12, 1'000'000'123, frame, as, &rows);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].matched_frame, 11);
  EXPECT_EQ(rows[1].matched_frame, -1);
  EXPECT_EQ(rows[2].matched_frame, 7);

  const ScratchDir scratch;
  const fs::path p = scratch.path() / "tracks.csv";
  write_tracks_csv(p, rows);
  EXPECT_FALSE(fs::exists(fs::path(p.string() + ".partial")));
  std::ifstream f(p);
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header.rfind("frame,timestamp_ns,track_id,bearing_rad", 0), 0u);
  const auto back = read_tracks_csv(p);
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back[i].frame, 12);
    EXPECT_EQ(back[i].timestamp_ns, 1'000'000'123);
    EXPECT_EQ(back[i].track_id, rows[i].track_id);
    EXPECT_NEAR(back[i].bearing, rows[i].bearing, 1e-9);
    EXPECT_NEAR(back[i].image_angle, rows[i].image_angle, 1e-9);
    EXPECT_EQ(back[i].edge_pixels, rows[i].edge_pixels);
    EXPECT_NEAR(back[i].r_outer, 180.25, 1e-9);
    EXPECT_EQ(back[i].matched_frame, rows[i].matched_frame);
    EXPECT_EQ(back[i].line, static_cast<int>(i));
    EXPECT_EQ(back[i].matched_line, rows[i].matched_line);
    EXPECT_EQ(back[i].crowded, i == 1);
    EXPECT_NEAR(back[i].annulus_fraction, 0.25 * (i + 1), 1e-4);
  }
  EXPECT_EQ(back[1].matched_line, -1);
  EXPECT_EQ(back[2].matched_line, 4);
  EXPECT_NEAR(back[0].distance, 0.25, 1e-6);
}

TEST(TracksCsv, MinimalColumnsInAnyOrder) {
  const ScratchDir scratch;
  const fs::path p = scratch.path() / "min.csv";
  write_text(p, "track_id,bearing_rad,frame,timestamp_ns\n4,0.5,3,100\n\n4,0.6,4,200\n");
  const auto rows = read_tracks_csv(p);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].frame, 4);
  EXPECT_EQ(rows[1].track_id, 4);
  EXPECT_EQ(rows[1].matched_frame, -1);  // unknown: evaluation falls back to frame order
  EXPECT_TRUE(std::isnan(rows[1].annulus_fraction));  // unknown: the calibration uses it
}

// A fraction not known (-1 in the file, NaN in memory) stays not known through a rewrite.
TEST(TracksCsv, UnknownAnnulusFractionRoundTrips) {
  const ScratchDir scratch;
  const fs::path p = scratch.path() / "f.csv";
  write_text(p,
             "frame,timestamp_ns,track_id,bearing_rad,annulus_fraction\n0,1,2,0.1,-1\n"
             "1,2,2,0.2,0.61\n");
  auto rows = read_tracks_csv(p);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_TRUE(std::isnan(rows[0].annulus_fraction));
  EXPECT_DOUBLE_EQ(rows[1].annulus_fraction, 0.61);
  write_tracks_csv(p, rows);
  rows = read_tracks_csv(p);
  EXPECT_TRUE(std::isnan(rows[0].annulus_fraction));
  EXPECT_DOUBLE_EQ(rows[1].annulus_fraction, 0.61);
}

TEST(TracksCsv, BadInputNamesFileAndLine) {
  const ScratchDir scratch;
  const fs::path& dir = scratch.path();
  auto expect_error = [&](const std::string& content, int line, const std::string& what) {
    const fs::path p = dir / "bad.csv";
    write_text(p, content);
    try {
      read_tracks_csv(p);
      FAIL() << "no error for: " << content;
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.csv"), std::string::npos) << e.what();
    }
  };
  expect_error("frame,timestamp_ns,bearing_rad\n", 1, "track_id");
  expect_error("frame,timestamp_ns,track_id,bearing_rad\n0,1,2,abc\n", 2, "bearing_rad");
  expect_error("frame,timestamp_ns,track_id,bearing_rad\n0,1,2,0.1\n1,2,3\n", 3, "fields");
  expect_error("frame,timestamp_ns,track_id,bearing_rad\n0,1,2,nan\n", 2, "");
  expect_error("frame,timestamp_ns,track_id,bearing_rad\n-1,1,2,0.1\n", 2, "negative frame");
  expect_error("frame,timestamp_ns,track_id,bearing_rad\n0,1,2,4.0\n", 2, "outside");
  expect_error("frame,timestamp_ns,track_id,bearing_rad,crowded\n0,1,2,0.1,2\n", 2, "crowded");
  expect_error("frame,timestamp_ns,track_id,bearing_rad,annulus_fraction\n0,1,2,0.1,7\n",
               2,
               "annulus_fraction");
  expect_error("", 0, "empty");
  EXPECT_THROW(read_tracks_csv(dir / "does_not_exist.csv"), InputError);
}

// Pixel checks on Fig. 22: a track crossing +-180 degrees is not drawn across the plot; an
// ordinary track is drawn between its detections.
TEST(TracksPlot, WrapIsBrokenAndTracksAreDrawn) {
  std::vector<TrackRow> rows;
  auto add = [&](std::int64_t frame, std::int64_t id, double deg) {
    TrackRow r;
    r.frame = frame;
    r.track_id = id;
    r.bearing = wrap_angle(deg2rad(deg));
    rows.push_back(r);
  };
  add(0, 0, 170);
  add(100, 0, -170);  // crosses +180 -> -180 between the two frames
  add(0, 1, -90);
  add(100, 1, -60);
  viz::TrackPlotOptions o;
  o.draw_ids = false;
  const cv::Mat img = viz::draw_tracks(rows, o);
  ASSERT_EQ(img.cols, o.width);
  ASSERT_EQ(img.rows, o.height);
  // Plot area as in draw_tracks: left 80, right 30, top 50, bottom 60.
  const double ax = 80, aw = o.width - 110, ay = 50, ah = o.height - 110;
  auto is_ink = [&](double frame, double deg) {
    const int x = static_cast<int>(ax + frame / 100.0 * aw);
    const int y = static_cast<int>(ay + (180.0 - deg) / 360.0 * ah);
    // Any non-white, non-grid pixel within 2 px.
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        const cv::Vec3b p = img.at<cv::Vec3b>(y + dy, x + dx);
        if (p[0] < 200 || p[1] < 200 || p[2] < 200) return true;
      }
    }
    return false;
  };
  // Track 1: drawn halfway (-75 degrees at frame 50).
  EXPECT_TRUE(is_ink(50, -75));
  // Track 0: pieces near the borders, nothing in the middle of the plot at frame 50.
  EXPECT_TRUE(is_ink(25, 175));
  EXPECT_TRUE(is_ink(75, -175));
  EXPECT_FALSE(is_ink(50, 0));
  EXPECT_FALSE(is_ink(50, 90));
  EXPECT_FALSE(is_ink(50, -30));
}

// Writes a Fig. 22 of a synthetic run for a look (OMNIVERT_PLOT_DIR) and checks the PNG.
TEST(TracksPlot, WritesPng) {
  std::vector<TrackRow> rows;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-kPi, kPi);
  std::int64_t next = 0;
  for (int line = 0; line < 40; ++line) {
    const int start = line < 20 ? 0 : static_cast<int>(std::abs(u(rng)) * 60);
    const int len = 40 + static_cast<int>(std::abs(u(rng)) * 60);
    const double b0 = u(rng), rate = 0.02 * u(rng);
    std::int64_t id = next++;
    for (int f = start; f < std::min(200, start + len); ++f) {
      if ((f + line) % 17 == 0) continue;  // a missed detection
      if (f == start + 50) id = next++;    // a false new entry
      TrackRow r;
      r.frame = f;
      r.track_id = id;
      r.bearing = wrap_angle(b0 + rate * f);
      rows.push_back(r);
    }
  }
  const char* env = std::getenv("OMNIVERT_PLOT_DIR");
  const ScratchDir scratch;
  const fs::path p = (env ? fs::path(env) : scratch.path()) / "tracks.png";
  viz::write_tracks_png(p, rows);
  const cv::Mat back = cv::imread(p.string());
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(back.cols, 1600);
  EXPECT_EQ(back.rows, 900);
}

}  // namespace
}  // namespace omnivert
