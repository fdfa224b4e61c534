// Inputs that crashed a fuzz harness (tests/fuzz/regressions/<harness>/,
// docs/validation.md#fuzzing), replayed through the harness's own code: each must now be read, or
// refused with an InputError (any other exception fails the test).

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz_messages.hpp"

namespace omnivert {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FuzzRegressions, DecoderInputsAreReadOrRefused) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(OMNIVERT_FUZZ_DIR "/regressions/decoders")) {
    SCOPED_TRACE(e.path().string());
    const std::vector<std::uint8_t> bytes = slurp(e.path());
    EXPECT_NO_THROW(fuzz::decode_selected(bytes.data(), bytes.size()));
    ++n;
  }
  EXPECT_GE(n, 2);
}

// A recording whose chunk records a huge uncompressed size (the MCAP harness's timeout: the
// whole size was allocated and cleared before decompressing).
TEST(FuzzRegressions, RecordingInputsAreReadOrRefused) {
  int n = 0;
  for (const char* format : {"mcap"}) {
    for (const auto& e :
         fs::directory_iterator(fs::path(OMNIVERT_FUZZ_DIR "/regressions") / format)) {
      SCOPED_TRACE(e.path().string());
      EXPECT_NO_THROW(fuzz::read_recording(e.path().string()));
      ++n;
    }
  }
  EXPECT_GE(n, 1);
}

// The empty raw image of the first regression: an InputError that says so.
TEST(FuzzRegressions, AnEmptyRawImageIsAnInputError) {
  const std::vector<std::uint8_t> bytes =
      slurp(OMNIVERT_FUZZ_DIR "/regressions/decoders/empty-rgb8-image");
  recording::TopicInfo topic{"/camera", "sensor_msgs/Image", 1};
  recording::Message m;
  m.topic = &topic;
  m.data = {bytes.data() + 1, bytes.size() - 1};
  recording::ImageSink sink(fs::path(testing::TempDir()), recording::Serialization::kRos1, false);
  std::string name;
  try {
    sink.add(m, "/camera #0", name);
    ADD_FAILURE() << "an empty image was written";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/camera #0: an empty image (width or height 0)");
  }
}

}  // namespace
}  // namespace omnivert
