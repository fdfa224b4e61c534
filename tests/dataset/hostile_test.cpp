// Hostile and extreme inputs to the readers (docs/validation.md#hostile-and-extreme-inputs):
// NaN and infinity in every numeric column and field, timestamps at the limits of int64,
// 100,000 frames, symbolic-link loops and files that are not regular files. Each either reads
// with the right numbers or throws an InputError naming the file, the line and the problem.

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <yaml-cpp/yaml.h>

#include "core/yaml_fields.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/match/tracks_io.hpp"

namespace omnivert::dataset {
namespace {

namespace fs = std::filesystem;
using ::testing::AnyOf;
using ::testing::Eq;
using ::testing::HasSubstr;

constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
// The ways a number can fail to be finite in a CSV cell or a YAML scalar.
const char* const kNonFiniteCsv[] = {"nan", "NaN", "inf", "-inf", "infinity", "1e999"};
const char* const kNonFiniteYaml[] = {".nan", ".inf", "-.inf", "1e999"};

// A valid two-frame dataset with ground truth; each test spoils one file.
class HostileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root = fs::temp_directory_path() / ("omnivert_hostile_" + std::to_string(::getpid()));
    fs::remove_all(root);
    fs::create_directories(root / "cam0" / "data");
    fs::create_directories(root / "wheel0");
    fs::create_directories(root / "ground_truth");
    write("cam0/sensor.yaml", "resolution: [16, 12]\ncenter: [8, 6]\nr_min: 2\nr_max: 5\n");
    write("cam0/data.csv", "#timestamp [ns],filename\n1000,a.png\n2000,a.png\n");
    ASSERT_TRUE(cv::imwrite(p("cam0/data/a.png"), cv::Mat1b(12, 16, std::uint8_t{9})));
    write("wheel0/sensor.yaml", "wheel_base: 0.4\nunit: meters\nodometry_k: 1.0e-5\n");
    write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n1000,0,0\n2000,0,0\n");
  }
  void TearDown() override { fs::remove_all(root); }

  void write(const std::string& rel, const std::string& text) {
    fs::remove(root / rel);
    std::ofstream(root / rel) << text;
  }
  std::string p(const std::string& rel) const { return (root / rel).string(); }
  std::string error() const {
    try {
      Dataset::load(root.string());
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  // The InputError message of read(), or "(no error)".
  template <class Read>
  static std::string error_of(Read read) {
    try {
      (void)read();
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path root;
};

TEST_F(HostileTest, NonFiniteNumbersInEveryCsvColumnAreRefusedWithFileAndLine) {
  for (const char* v : kNonFiniteCsv) {
    const std::string s(v);
    SCOPED_TRACE(s);
    write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n1000,0,0\n2000," + s + ",0\n");
    EXPECT_EQ(
        error(),
        p("wheel0/data.csv") + ":3: cannot parse left wheel value '" + s + "' as a finite number");
    write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n1000,0,0\n2000,0," + s + "\n");
    EXPECT_EQ(
        error(),
        p("wheel0/data.csv") + ":3: cannot parse right wheel value '" + s + "' as a finite number");
    write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n1000,0,0\n" + s + ",0,0\n");
    EXPECT_THAT(error(), HasSubstr(p("wheel0/data.csv") + ":3: cannot parse timestamp"));
    write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n1000,0,0\n2000,0,0\n");
    write("cam0/data.csv", "#timestamp [ns],filename\n1000,a.png\n" + s + ",a.png\n");
    EXPECT_THAT(error(), HasSubstr(p("cam0/data.csv") + ":3: cannot parse timestamp"));
    write("cam0/data.csv", "#timestamp [ns],filename\n1000,a.png\n2000,a.png\n");
  }
}

TEST_F(HostileTest, NonFiniteNumbersInGroundTruthAreReportedNotFatal) {
  const std::string poses = "#timestamp [ns],x [m],y [m],theta [rad]\n1000,0,0,0\n";
  const std::string lines = "#timestamp [ns],frame,line_id,bearing [rad],r_inner,r_outer\n";
  for (const char* v : kNonFiniteCsv) {
    const std::string s(v);
    SCOPED_TRACE(s);
    const std::string pose_rows[] = {"2000," + s + ",0,0", "2000,0," + s + ",0", "2000,0,0," + s};
    const char* pose_columns[] = {"x", "y", "theta"};
    for (int c = 0; c < 3; ++c) {
      write("ground_truth/poses.csv", poses + pose_rows[c] + "\n");
      const Dataset d = Dataset::load(root.string());  // ground truth does not stop the load
      EXPECT_FALSE(d.ground_truth().has_value());
      EXPECT_EQ(d.ground_truth_error(),
                p("ground_truth/poses.csv") + ":3: cannot parse " + pose_columns[c] + " '" + s +
                    "' as a finite number");
    }
    fs::remove(root / "ground_truth/poses.csv");
    const std::string line_rows[] = {
        "1000,0,0," + s + ",2,5", "1000,0,0,0.5," + s + ",5", "1000,0,0,0.5,2," + s};
    const char* line_columns[] = {"bearing", "r_inner", "r_outer"};
    for (int c = 0; c < 3; ++c) {
      write("ground_truth/lines.csv", lines + line_rows[c] + "\n");
      EXPECT_EQ(Dataset::load(root.string()).ground_truth_error(),
                p("ground_truth/lines.csv") + ":2: cannot parse " + line_columns[c] + " '" + s +
                    "' as a finite number");
    }
    write("ground_truth/lines.csv", lines + "1000," + s + ",0,0.5,2,5\n");
    EXPECT_EQ(Dataset::load(root.string()).ground_truth_error(),
              p("ground_truth/lines.csv") + ":2: cannot parse frame '" + s + "' as an integer");
    fs::remove(root / "ground_truth/lines.csv");
  }
}

TEST_F(HostileTest, NonFiniteNumbersInEveryYamlFieldAreRefusedWithFileAndLine) {
  struct Field {
    const char* file;
    const char* key;
    std::string before, after;  // the file's text around "key: value"
  };
  const std::string cam = "resolution: [16, 12]\n";
  const std::vector<Field> fields = {
      {"cam0/sensor.yaml", "r_min", cam + "center: [8, 6]\n", "r_max: 5\n"},
      {"cam0/sensor.yaml", "r_max", cam + "center: [8, 6]\nr_min: 2\n", ""},
      {"cam0/sensor.yaml", "bearing_sign", cam, ""},
      {"cam0/sensor.yaml", "xi", cam, "gamma: 100\n"},
      {"cam0/sensor.yaml", "gamma", cam + "xi: 0.9\n", ""},
      {"cam0/sensor.yaml", "bit_depth", cam, ""},
      {"wheel0/sensor.yaml", "wheel_base", "unit: meters\n", ""},
      {"wheel0/sensor.yaml", "odometry_k", "wheel_base: 0.4\n", ""},
      {"wheel0/sensor.yaml",
       "ticks_per_meter_left",
       "wheel_base: 0.4\nunit: ticks\n",
       "ticks_per_meter_right: 100\n"},
      {"wheel0/sensor.yaml",
       "counter_bits",
       "wheel_base: 0.4\nunit: ticks\n"
       "ticks_per_meter_left: 100\nticks_per_meter_right: 100\n",
       ""},
  };
  const std::string cam_ok = cam + "center: [8, 6]\nr_min: 2\nr_max: 5\n";
  const std::string wheel_ok = "wheel_base: 0.4\nunit: meters\n";
  for (const char* v : kNonFiniteYaml) {
    for (const Field& f : fields) {
      SCOPED_TRACE(std::string(f.key) + ": " + v);
      write(f.file, f.before + f.key + ": " + v + "\n" + f.after);
      const int line = 1 + static_cast<int>(std::count(f.before.begin(), f.before.end(), '\n'));
      // 1e999 overflows the conversion itself: "must be a number", the others "must be finite".
      const std::string at = p(f.file) + ":" + std::to_string(line) + ": field '" + f.key;
      EXPECT_THAT(
          error(),
          AnyOf(Eq(at + "' must be finite"), Eq(at + "' must be a number, got '" + v + "'")));
      write("cam0/sensor.yaml", cam_ok);
      write("wheel0/sensor.yaml", wheel_ok);
    }
    for (const char* seq : {"resolution", "center"}) {
      SCOPED_TRACE(std::string(seq) + ": " + v);
      write("cam0/sensor.yaml",
            std::string(seq == std::string("center") ? cam : "") + seq + ": [8, " + v + "]\n");
      EXPECT_THAT(error(), HasSubstr(p("cam0/sensor.yaml") + ":"));
      write("cam0/sensor.yaml", cam_ok);
    }
    write("ground_truth/extrinsics.yaml", std::string("phi: 0.1\nrho: ") + v + "\npsi: 0\n");
    EXPECT_THAT(Dataset::load(root.string()).ground_truth_error(),
                HasSubstr(p("ground_truth/extrinsics.yaml") + ":2: field 'rho' must be"));
    fs::remove(root / "ground_truth/extrinsics.yaml");
  }
}

TEST_F(HostileTest, NonFiniteNumbersInEveryTracksColumnAreRefusedWithFileAndLine) {
  const std::string header =
      "frame,timestamp_ns,track_id,bearing_rad,image_angle_rad,edge_pixels,r_inner,r_outer,"
      "matched_frame,distance,line,matched_line,crowded\n";
  const std::string good = "0,1000,0,0.5,0.5,80,60.0,200.0,-1,0.0,0,-1,0";
  const auto path = root / "tracks.csv";
  for (int column = 0; column < 13; ++column) {
    for (const char* v : kNonFiniteCsv) {
      SCOPED_TRACE(std::to_string(column) + ": " + v);
      std::vector<std::string> cells;
      std::string cell;
      for (char c : good + ",") {
        if (c == ',') {
          cells.push_back(cell);
          cell.clear();
        } else {
          cell += c;
        }
      }
      cells[static_cast<std::size_t>(column)] = v;
      std::string row;
      for (const auto& c : cells) row += (row.empty() ? "" : ",") + c;
      std::ofstream(path) << header << good << "\n" << row << "\n";
      try {
        (void)read_tracks_csv(path);
        ADD_FAILURE() << "read " << row;
      } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr(path.string() + ":3: column '"));
      }
    }
  }
}

TEST_F(HostileTest, TimestampsAtTheLimitsOfInt64) {
  const std::string max = std::to_string(kMax);
  write("cam0/data.csv", "#timestamp [ns],filename\n0,a.png\n" + max + ",a.png\n");
  write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n0,0,0\n" + max + ",1,2\n");
  Dataset d = Dataset::load(root.string());
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.images()[1].timestamp_ns, kMax);
  EXPECT_DOUBLE_EQ(d.travel_at_images()[1].right, 2.0);
  EXPECT_NEAR(d.travel_at(kMax / 2).left, 0.5, 1e-12);
  // A time offset that would carry a stamp past the limits clamps to the wheel data's ends.
  for (std::int64_t offset : {std::int64_t{-10'000'000'000}, std::int64_t{10'000'000'000}}) {
    EXPECT_EQ(d.set_image_time_offset(offset), 1);
    EXPECT_DOUBLE_EQ(d.travel_at_images()[offset < 0 ? 1 : 0].left, offset < 0 ? 1.0 : 0.0);
  }
  // One past the limit, and a negative stamp, are refused.
  write("cam0/data.csv", "#timestamp [ns],filename\n0,a.png\n9223372036854775808,a.png\n");
  EXPECT_EQ(error(),
            p("cam0/data.csv") +
                ":3: cannot parse timestamp '9223372036854775808' (expected a "
                "non-negative integer in ns)");
  write("cam0/data.csv", "#timestamp [ns],filename\n-1,a.png\n");
  EXPECT_THAT(error(), HasSubstr(":2: cannot parse timestamp '-1'"));
}

TEST_F(HostileTest, HundredThousandFramesLoad) {
  constexpr int kFrames = 100'000;
  std::string cam = "#timestamp [ns],filename\n", wheel = "#timestamp [ns],left [m],right [m]\n";
  for (int i = 0; i < kFrames; ++i) {
    const std::string t = std::to_string(1'000'000'000LL + 33'333'333LL * i);
    cam += t + ",a.png\n";
    wheel += t + "," + std::to_string(0.001 * i) + "," + std::to_string(0.002 * i) + "\n";
  }
  write("cam0/data.csv", cam);
  write("wheel0/data.csv", wheel);
  const Dataset d = Dataset::load(root.string());
  ASSERT_EQ(d.size(), static_cast<std::size_t>(kFrames));
  EXPECT_NEAR(d.travel_at_images().back().left, 0.001 * (kFrames - 1), 1e-9);
  EXPECT_NEAR(d.travel_at_images().back().right, 0.002 * (kFrames - 1), 1e-9);
}

TEST_F(HostileTest, SymlinkLoopsAndFilesThatAreNotFilesAreRefused) {
  // A loop of symbolic links in place of a file, of an image and of a folder.
  fs::remove(root / "wheel0/data.csv");
  fs::create_symlink("data.csv", root / "wheel0/data.csv");
  EXPECT_EQ(error(), p("wheel0/data.csv") + ": is a loop of symbolic links");
  fs::remove(root / "wheel0/data.csv");
  fs::create_symlink(root / "wheel0/loop-b", root / "wheel0/loop-a");
  fs::create_symlink(root / "wheel0/loop-a", root / "wheel0/loop-b");
  fs::create_symlink(root / "wheel0/loop-a", root / "wheel0/data.csv");
  EXPECT_EQ(error(), p("wheel0/data.csv") + ": is a loop of symbolic links");
  fs::remove(root / "wheel0/data.csv");
  write("wheel0/data.csv", "#timestamp [ns],left [m],right [m]\n1000,0,0\n2000,0,0\n");
  fs::create_symlink("b.png", root / "cam0/data/b.png");
  write("cam0/data.csv", "#timestamp [ns],filename\n1000,a.png\n2000,b.png\n");
  EXPECT_EQ(error(), p("cam0/data.csv") + ":3: image file 'b.png' not found in cam0/data/");
  // A folder, and a FIFO that would block a reader forever, in place of a file. (Permission
  // bits do not stop root, who runs CI, so these stand for a file that cannot be read.)
  write("cam0/data.csv", "#timestamp [ns],filename\n1000,a.png\n2000,a.png\n");
  fs::remove(root / "wheel0/data.csv");
  fs::create_directory(root / "wheel0/data.csv");
  EXPECT_EQ(error(), p("wheel0/data.csv") + ": is a directory");
  fs::remove(root / "wheel0/data.csv");
  ASSERT_EQ(::mkfifo(p("wheel0/data.csv").c_str(), 0600), 0);
  EXPECT_EQ(error(),
            p("wheel0/data.csv") + ": is not a regular file (a FIFO, a socket or a device)");
  fs::remove(root / "cam0/sensor.yaml");
  ASSERT_EQ(::mkfifo(p("cam0/sensor.yaml").c_str(), 0600), 0);
  EXPECT_EQ(error(),
            p("cam0/sensor.yaml") + ": is not a regular file (a FIFO, a socket or a device)");
}

// Found by the tracks.csv fuzz harness (tests/fuzz/regressions/tracks): a header naming a
// column twice made rows of fewer fields pass the width check and be read past their end.
TEST_F(HostileTest, TracksHeaderNamingAColumnTwiceIsRefused) {
  const auto path = root / "tracks.csv";
  std::ofstream(path) << "frame,timestamp_ns,track_id,bearing_rad,frame\n0,1,0,0.5\n";
  EXPECT_EQ(error_of([&] { return read_tracks_csv(path); }),
            path.string() + ":1: column 'frame' appears twice in the header");
  const fs::path found = OMNIVERT_FUZZ_DIR "/regressions/tracks/duplicate-column.csv";
  EXPECT_THROW((void)read_tracks_csv(found), InputError);
}

// Found by the YAML fuzz harness (tests/fuzz/regressions/yaml): the line of a key that is
// absent threw yaml-cpp's InvalidNode instead of giving no line.
TEST_F(HostileTest, LineOfAnAbsentYamlKeyIsZero) {
  const std::string path = OMNIVERT_FUZZ_DIR "/regressions/yaml/absent-key-line.yaml";
  try {
    const YAML::Node root = yaml::load_file(path);
    EXPECT_EQ(yaml::line_of(root["psi"]), 0);
  } catch (const InputError&) {
  }
  write("prior.yaml", "phi: 0.1\nrho: 0.2\n");
  const YAML::Node y = yaml::load_file(p("prior.yaml"));
  EXPECT_EQ(yaml::line_of(y["rho"]), 2);
  EXPECT_EQ(yaml::line_of(y["psi"]), 0);
}

// Found by the cam0/sensor.yaml fuzz harness (tests/fuzz/regressions/cam0_sensor): a
// resolution of 5.6e44 pixels was converted to int (undefined behaviour).
TEST_F(HostileTest, HugeResolutionIsRefused) {
  const std::string found = OMNIVERT_FUZZ_DIR "/regressions/cam0_sensor/huge-resolution.yaml";
  EXPECT_EQ(error_of([&] { return load_camera_geometry(found); }),
            found + ":1: field 'resolution' must hold two whole numbers of pixels, 1 to 100000");
  write("sensor.yaml", "resolution: [100001, 480]\n");
  EXPECT_THROW((void)load_camera_geometry(p("sensor.yaml")), InputError);
  write("sensor.yaml", "resolution: [100000, 480]\n");
  EXPECT_EQ(load_camera_geometry(p("sensor.yaml")).width, 100000);
}

// Found by the image fuzz harness (tests/fuzz/regressions/image): a file that is no image made
// OpenCV's DICOM reader (GDCM) fail an assertion and abort the program.
TEST_F(HostileTest, FileOfNoImageFormatIsRefusedBeforeDecoding) {
  const std::string found = OMNIVERT_FUZZ_DIR "/regressions/image/gdcm-assertion.bin";
  EXPECT_THAT(error_of([&] { return read_image(found); }),
              ::testing::HasSubstr("not a readable image (it does not start with the signature"));
  cv::imwrite(p("ok.png"), cv::Mat(4, 5, CV_8UC1, cv::Scalar(7)));
  EXPECT_EQ(read_image(p("ok.png")).cols, 5);
  cv::imwrite(p("ok.pgm"), cv::Mat(4, 5, CV_8UC1, cv::Scalar(7)));
  EXPECT_EQ(read_image(p("ok.pgm")).rows, 4);
}

// The second file the image harness found starts "P55": PNM-like to a two-byte test, refused
// by OpenCV's PNM decoder, and then claimed by the DICOM reader ("DICM" at byte 128), which
// aborts. Every start that read_image lets through must be claimed by its own decoder: the
// file's DICOM tail behind each accepted signature is refused with an InputError (an abort
// here ends the test program).
TEST_F(HostileTest, NoAcceptedSignatureLetsAFileThroughToTheDicomReader) {
  const std::string found = OMNIVERT_FUZZ_DIR "/regressions/image/gdcm-assertion-pnm-like.bin";
  std::ifstream in(found, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 132u);
  ASSERT_EQ(bytes.substr(128, 4), "DICM");
  EXPECT_THAT(error_of([&] { return read_image(found); }),
              ::testing::HasSubstr("not a readable image (it does not start with the signature"));
  const std::vector<std::string> starts = {std::string("\x89PNG\r\n\x1a\n", 8),
                                           "\xff\xd8\xff",
                                           std::string("II*\0", 4),
                                           std::string("MM\0*", 4),
                                           "BM",
                                           "P5 ",
                                           "P6\n",
                                           "P1\t"};
  for (const std::string& start : starts) {
    std::string file = bytes;
    file.replace(0, start.size(), start);
    const std::string path = p("hostile.img");
    {
      std::ofstream out(path, std::ios::binary);
      out << file;
    }
    EXPECT_NE(error_of([&] { return read_image(path); }), "(no error)") << start;
  }
}

}  // namespace
}  // namespace omnivert::dataset
