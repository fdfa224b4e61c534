// libFuzzer harness of the recording readers (open_recording: ROS 1 bag, MCAP, rosbag2
// sqlite3, recognised by their magic bytes) and of every message they hold, decoded as
// `omnivert import` would decode it. Built three times (fuzz_ros1_bag, fuzz_mcap, fuzz_db3),
// each seeded with its format's fixtures from tests/recording/fixtures.

#include <cstdint>

#include "fuzz_messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = (omnivert::fuzz::scratch() / "recording").string();
  omnivert::fuzz::write_file(path, omnivert::fuzz::as_text(data, size));
  omnivert::fuzz::read_recording(path);
  return 0;
}
