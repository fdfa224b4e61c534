#pragma once
// The readers behind open_recording (recording.hpp).

#include <memory>
#include <string>

#include "omnivert/recording/recording.hpp"

namespace omnivert::recording {

std::unique_ptr<Recording> open_ros1_bag(const std::string& path);
std::unique_ptr<Recording> open_mcap(const std::string& path);
// A rosbag2 sqlite3 file; `message_zstd`: each message's data is a zstd frame
// (metadata.yaml: compression_mode MESSAGE, compression_format zstd).
std::unique_ptr<Recording> open_db3(const std::string& path, bool message_zstd);

}  // namespace omnivert::recording
