// ROS 1 bag format 2.0 (http://wiki.ros.org/Bags/Format/2.0): "#ROSBAG V2.0\n", then records
// of <header_len u32><header: fields <len u32>name=value><data_len u32><data>. The bag header
// record (op 0x03) points at the index at the end (connections op 0x07, chunk infos op 0x06
// with each connection's message count); chunks (op 0x05, none|bz2|lz4) hold connection and
// message data (op 0x02) records. We read the index, then the chunks one at a time.

#include <algorithm>
#include <map>

#include "recording/bytes.hpp"
#include "recording/file_reader.hpp"
#include "recording/readers.hpp"

namespace omnivert::recording {

namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicLen = 13;

struct Header {
  std::map<std::string, std::span<const std::uint8_t>> fields;
  std::uint8_t op = 0;

  template <typename T>
  T get(const std::string& name, const std::string& what) const {
    auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != sizeof(T)) {
      throw InputError(what + ": record without a valid '" + name + "' field");
    }
    T v;
    std::memcpy(&v, it->second.data(), sizeof(T));
    return v;
  }
  std::string str(const std::string& name) const {
    auto it = fields.find(name);
    if (it == fields.end()) return {};
    return std::string(reinterpret_cast<const char*>(it->second.data()), it->second.size());
  }
};

Header parse_header(std::span<const std::uint8_t> bytes, const std::string& what) {
  Header h;
  ByteReader r(bytes, what);
  while (!r.done()) {
    const auto len = r.get<std::uint32_t>();
    auto field = r.bytes(len);
    auto eq = std::find(field.begin(), field.end(), static_cast<std::uint8_t>('='));
    if (eq == field.end()) r.fail("a header field without '='");
    const std::size_t k = static_cast<std::size_t>(eq - field.begin());
    h.fields[std::string(reinterpret_cast<const char*>(field.data()), k)] = field.subspan(k + 1);
  }
  if (auto it = h.fields.find("op"); it != h.fields.end() && it->second.size() == 1)
    h.op = it->second[0];
  return h;
}

// One record read from a byte span: its header and its data.
struct Record {
  Header header;
  std::span<const std::uint8_t> data;
};

Record next_record(ByteReader& r) {
  const auto hlen = r.get<std::uint32_t>();
  auto hbytes = r.bytes(hlen);
  Record rec;
  rec.header = parse_header(hbytes, "ROS 1 bag record");
  const auto dlen = r.get<std::uint32_t>();
  rec.data = r.bytes(dlen);
  return rec;
}

struct ChunkInfo {
  std::uint64_t pos = 0;
};

class Ros1Bag final : public Recording {
 public:
  explicit Ros1Bag(const std::string& path) : file_(path) {
    path_ = path;
    read_index();
  }
  std::string format() const override { return "ROS 1 bag"; }
  Serialization serialization() const override { return Serialization::kRos1; }

  void read(const std::vector<std::string>& topics,
            const MessageFn& on_message,
            const ProgressFn& progress) override {
    std::map<std::uint32_t, const TopicInfo*> wanted;
    for (const auto& [conn, topic_index] : conn_topic_) {
      if (std::find(topics.begin(), topics.end(), topics_[topic_index].name) != topics.end()) {
        wanted[conn] = &topics_[topic_index];
      }
    }
    std::vector<std::uint64_t> counts(topics_.size(), 0);
    for (const ChunkInfo& c : chunks_) {
      if (progress) progress(c.pos, file_.size());
      read_chunk(c.pos);
      ByteReader r(chunk_, path_ + ": chunk at byte " + std::to_string(c.pos));
      while (!r.done()) {
        const Record rec = next_record(r);
        if (rec.header.op != 0x02) continue;
        const auto conn = rec.header.get<std::uint32_t>("conn", path_);
        auto it = wanted.find(conn);
        if (it == wanted.end()) continue;
        const auto t = time_ns(rec.header);
        Message m;
        m.topic = it->second;
        m.log_time_ns = t;
        m.index = counts[static_cast<std::size_t>(it->second - topics_.data())]++;
        m.data = rec.data;
        on_message(m);
      }
    }
    if (progress) progress(file_.size(), file_.size());
  }

 private:
  static std::int64_t time_ns(const Header& h) {
    auto it = h.fields.find("time");
    if (it == h.fields.end() || it->second.size() != 8)
      throw InputError("ROS 1 bag: message without a time");
    std::uint32_t s, ns;
    std::memcpy(&s, it->second.data(), 4);
    std::memcpy(&ns, it->second.data() + 4, 4);
    return static_cast<std::int64_t>(s) * 1'000'000'000 + ns;
  }

  // Reads the record at `offset` (header and data) into buf_; returns the header.
  Header record_at(std::uint64_t offset, std::uint64_t* next, const std::string& what) {
    const auto hlen = file_.value<std::uint32_t>(offset, what);
    file_.read(offset + 4, hlen, hbuf_, what);
    Header h = parse_header(hbuf_, path_ + ": " + what);
    const auto dlen = file_.value<std::uint32_t>(offset + 4 + hlen, what);
    file_.read(offset + 8 + hlen, dlen, buf_, what);
    *next = offset + 8 + hlen + dlen;
    return h;
  }

  void read_index() {
    std::vector<std::uint8_t> magic;
    if (file_.size() < kMagicLen) throw InputError(path_, 0, "too short for a ROS 1 bag");
    file_.read(0, kMagicLen, magic, "the magic");
    if (std::memcmp(magic.data(), kMagic, kMagicLen) != 0) {
      throw InputError(path_, 0, "not a ROS 1 bag of format 2.0 (no '#ROSBAG V2.0' line)");
    }
    std::uint64_t next = 0;
    const Header bh = record_at(kMagicLen, &next, "the bag header");
    const auto index_pos = bh.get<std::uint64_t>("index_pos", path_);
    const auto conn_count = bh.get<std::uint32_t>("conn_count", path_);
    const auto chunk_count = bh.get<std::uint32_t>("chunk_count", path_);
    if (index_pos == 0 || index_pos >= file_.size()) {
      throw InputError(path_,
                       0,
                       "the bag's index is missing (index at byte " + std::to_string(index_pos) +
                           ", file of " + std::to_string(file_.size()) +
                           " bytes): the recording is truncated or was not closed; "
                           "`rosbag reindex` repairs such a bag");
    }
    std::uint64_t pos = index_pos;
    std::map<std::string, std::size_t> topic_index;
    for (std::uint32_t i = 0; i < conn_count; ++i) {
      const Header h = record_at(pos, &pos, "connection record " + std::to_string(i));
      if (h.op != 0x07) throw InputError(path_, 0, "expected a connection record in the index");
      const auto conn = h.get<std::uint32_t>("conn", path_);
      const Header ch = parse_header(buf_, path_ + ": connection header");
      const std::string topic = h.str("topic");
      auto [it, added] = topic_index.try_emplace(topic, topics_.size());
      if (added) topics_.push_back({topic, ch.str("type"), 0});
      conn_topic_[conn] = it->second;
    }
    for (std::uint32_t i = 0; i < chunk_count; ++i) {
      const Header h = record_at(pos, &pos, "chunk info record " + std::to_string(i));
      if (h.op != 0x06) throw InputError(path_, 0, "expected a chunk info record in the index");
      chunks_.push_back({h.get<std::uint64_t>("chunk_pos", path_)});
      ByteReader r(buf_, path_ + ": chunk info");
      while (!r.done()) {
        const auto conn = r.get<std::uint32_t>();
        const auto count = r.get<std::uint32_t>();
        if (auto it = conn_topic_.find(conn); it != conn_topic_.end())
          topics_[it->second].count += count;
      }
    }
    std::sort(chunks_.begin(), chunks_.end(), [](auto& a, auto& b) { return a.pos < b.pos; });
  }

  void read_chunk(std::uint64_t pos) {
    std::uint64_t next = 0;
    const std::string what = "chunk at byte " + std::to_string(pos);
    const Header h = record_at(pos, &next, what);
    if (h.op != 0x05) throw InputError(path_, 0, what + " is not a chunk record");
    const std::string compression = h.str("compression");
    const auto size = h.get<std::uint32_t>("size", path_);
    if (compression == "none") {
      chunk_.assign(buf_.begin(), buf_.end());
    } else if (compression == "bz2") {
      decompress_bz2(buf_, size, chunk_, path_ + ": " + what);
    } else if (compression == "lz4") {
      decompress_lz4_frame(buf_, size, chunk_, path_ + ": " + what);
    } else {
      throw InputError(
          path_,
          0,
          what + ": compression '" + compression + "' is not one we read (none, bz2, lz4)");
    }
  }

  FileReader file_;
  std::map<std::uint32_t, std::size_t> conn_topic_;
  std::vector<ChunkInfo> chunks_;
  std::vector<std::uint8_t> hbuf_, buf_, chunk_;
};

}  // namespace

std::unique_ptr<Recording> open_ros1_bag(const std::string& path) {
  return std::make_unique<Ros1Bag>(path);
}

}  // namespace omnivert::recording
