// libFuzzer harness of the message decoders alone (sensor_msgs/Image, CompressedImage,
// JointState, nav_msgs/Odometry in ROS 1 serialisation and CDR) and of the image writer of
// `omnivert import`. The first byte chooses the message type and the serialisation; the rest
// is the message. Seeds: the messages of the recording fixtures (fuzz_seed_messages).

#include <cstdint>

#include "fuzz_messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  omnivert::fuzz::decode_selected(data, size);
  return 0;
}
