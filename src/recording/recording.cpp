#include "omnivert/recording/recording.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "omnivert/core/error.hpp"
#include "recording/readers.hpp"

namespace omnivert::recording {

namespace fs = std::filesystem;

const TopicInfo* Recording::find(const std::string& name) const {
  for (const TopicInfo& t : topics_)
    if (t.name == name) return &t;
  return nullptr;
}

std::string normalized_type(const std::string& type) {
  std::string t = type;
  if (const auto p = t.find("/msg/"); p != std::string::npos) t.erase(p + 1, 4);
  return t;
}

namespace {

// metadata.yaml of a rosbag2 folder: the storage files and the compression.
struct Rosbag2Meta {
  std::vector<std::string> files;
  bool message_zstd = false;
  bool file_compressed = false;
};

Rosbag2Meta read_metadata(const fs::path& dir) {
  Rosbag2Meta m;
  const fs::path yaml = dir / "metadata.yaml";
  if (!fs::exists(yaml)) return m;
  try {
    const YAML::Node info = YAML::LoadFile(yaml.string())["rosbag2_bagfile_information"];
    for (const auto& f : info["relative_file_paths"])
      m.files.push_back((dir / f.as<std::string>()).string());
    const std::string format =
        info["compression_format"] ? info["compression_format"].as<std::string>() : "";
    const std::string mode =
        info["compression_mode"] ? info["compression_mode"].as<std::string>() : "";
    if (!format.empty() && format != "zstd") {
      throw InputError(
          yaml.string(), 0, "compression_format '" + format + "' is not one we read (zstd)");
    }
    m.message_zstd = format == "zstd" && (mode == "MESSAGE" || mode == "message");
    m.file_compressed = format == "zstd" && (mode == "FILE" || mode == "file");
  } catch (const YAML::Exception& e) {
    throw InputError(yaml.string(), 0, std::string("does not parse: ") + e.what());
  }
  return m;
}

std::string magic_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot be opened for reading");
  char buf[16] = {};
  in.read(buf, sizeof buf);
  return std::string(buf, static_cast<std::size_t>(in.gcount()));
}

}  // namespace

std::unique_ptr<Recording> open_recording(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, 0, "recording not found");
  std::string file = path;
  Rosbag2Meta meta;
  if (fs::is_directory(path, ec)) {
    meta = read_metadata(path);
    if (meta.files.empty()) {
      for (const auto& e : fs::directory_iterator(path)) {
        const auto ext = e.path().extension();
        if (ext == ".db3" || ext == ".mcap") meta.files.push_back(e.path().string());
      }
      std::sort(meta.files.begin(), meta.files.end());
    }
    if (meta.files.empty()) throw InputError(path, 0, "a folder without a .db3 or .mcap file");
    if (meta.files.size() > 1) {
      throw InputError(path,
                       0,
                       "a bag split into " + std::to_string(meta.files.size()) +
                           " files; import each file on its own");
    }
    if (meta.file_compressed) {
      throw InputError(path,
                       0,
                       "the bag is compressed file by file (compression_mode FILE); "
                       "decompress it first (`zstd -d`) and import the .db3 or .mcap");
    }
    file = meta.files.front();
  } else {
    meta = read_metadata(fs::path(path).parent_path());
  }
  const std::string magic = magic_of(file);
  if (magic.rfind("#ROSBAG V2.0", 0) == 0 ||
      (magic.rfind("#ROSBAG", 0) == 0 && magic.size() < 13)) {
    return open_ros1_bag(file);
  }
  if (magic.rfind("#ROSBAG", 0) == 0)
    throw InputError(file, 0, "a ROS 1 bag of a version other than 2.0");
  if (magic.size() >= 8 && std::memcmp(magic.data(), "\x89MCAP0\r\n", 8) == 0)
    return open_mcap(file);
  if (magic.rfind("SQLite format 3", 0) == 0) return open_db3(file, meta.message_zstd);
  if (magic.size() >= 4 && std::memcmp(magic.data(), "\x28\xb5\x2f\xfd", 4) == 0) {
    throw InputError(file, 0, "a zstd-compressed file; decompress it first (`zstd -d`)");
  }
  throw InputError(file, 0, "not a recording we read (ROS 1 bag, ROS 2 .db3 or .mcap)");
}

}  // namespace omnivert::recording
