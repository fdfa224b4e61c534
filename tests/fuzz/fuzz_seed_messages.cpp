// Writes the first message of each decoded type in the given recordings as seeds of the
// decoder harness: the selector byte of fuzz_decoders.cpp, then the message's bytes.
//   fuzz_seed_messages OUT_DIR RECORDING...

#include <cstdio>
#include <fstream>
#include <set>
#include <string>

#include "omnivert/recording/recording.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: fuzz_seed_messages OUT_DIR RECORDING...\n");
    return 2;
  }
  namespace r = omnivert::recording;
  const std::string out = argv[1];
  for (int i = 2; i < argc; ++i) {
    auto rec = r::open_recording(argv[i]);
    const int cdr = rec->serialization() == r::Serialization::kCdr ? 4 : 0;
    std::set<int> done;
    std::vector<std::string> names;
    for (const auto& t : rec->topics()) names.push_back(t.name);
    rec->read(names, [&](const r::Message& m) {
      const std::string t = r::normalized_type(m.topic->type);
      const int kind = t == "sensor_msgs/Image"             ? 0
                       : t == "sensor_msgs/CompressedImage" ? 1
                       : t == "sensor_msgs/JointState"      ? 2
                       : t == "nav_msgs/Odometry"           ? 3
                                                            : -1;
      if (kind < 0 || !done.insert(kind).second) return;
      const std::string base = std::string(argv[i]);
      const std::string name =
          out + "/" + base.substr(base.find_last_of('/') + 1) + "-" + std::to_string(kind + cdr);
      std::ofstream f(name, std::ios::binary);
      const char selector = static_cast<char>(kind + cdr);
      f.write(&selector, 1);
      f.write(reinterpret_cast<const char*>(m.data.data()),
              static_cast<std::streamsize>(m.data.size()));
    });
  }
  return 0;
}
