// MCAP (https://mcap.dev/spec): magic "\x89MCAP0\r\n", records <opcode u8><length u64><content>,
// the same magic at the end after the footer. Channels (0x04) and schemas (0x03) come before
// their messages (0x05), at the top level or inside chunks (0x06: none, lz4 frame, zstd).
// Topics and counts come from the summary's Statistics record (0x0B) when there is one, else
// from a pass over the file. Messages are read one chunk at a time.

#include <algorithm>
#include <cstring>
#include <map>

#include "recording/bytes.hpp"
#include "recording/file_reader.hpp"
#include "recording/readers.hpp"

namespace omnivert::recording {

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
enum Op : std::uint8_t {
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kStatistics = 0x0B,
  kDataEnd = 0x0F
};

std::string str(ByteReader& r) { return r.string(r.get<std::uint32_t>()); }

class Mcap final : public Recording {
 public:
  explicit Mcap(const std::string& path) : file_(path) {
    path_ = path;
    std::vector<std::uint8_t> m;
    file_.read(0, 8, m, "the magic");
    if (std::memcmp(m.data(), kMagic, 8) != 0)
      throw InputError(path, 0, "not an MCAP file (no magic)");
    if (file_.size() < 8 + 29 + 8) throw InputError(path, 0, "truncated MCAP file (no footer)");
    file_.read(file_.size() - 8, 8, m, "the closing magic");
    if (std::memcmp(m.data(), kMagic, 8) != 0) {
      throw InputError(path,
                       0,
                       "the MCAP file is truncated or was not closed (no closing magic; "
                       "`mcap recover` repairs such a file)");
    }
    if (!read_summary()) scan({}, nullptr, nullptr, true);
  }
  std::string format() const override { return "MCAP"; }
  Serialization serialization() const override {
    return ros1_ ? Serialization::kRos1 : Serialization::kCdr;
  }

  void read(const std::vector<std::string>& topics,
            const MessageFn& on_message,
            const ProgressFn& progress) override {
    scan(topics, &on_message, &progress, false);
  }

 private:
  // Schemas and channels of a record; returns false for other records.
  bool definition(std::uint8_t op, ByteReader& r) {
    if (op == kSchema) {
      const auto id = r.get<std::uint16_t>();
      schemas_[id] = str(r);
      return true;
    }
    if (op != kChannel) return false;
    const auto id = r.get<std::uint16_t>();
    const auto schema = r.get<std::uint16_t>();
    const std::string topic = str(r);
    const std::string encoding = str(r);
    if (channels_.count(id)) return true;
    ros1_ = encoding == "ros1";
    auto it =
        std::find_if(topics_.begin(), topics_.end(), [&](auto& t) { return t.name == topic; });
    if (it == topics_.end()) {
      topics_.push_back({topic, schemas_.count(schema) ? schemas_[schema] : std::string("?"), 0});
      it = topics_.end() - 1;
    }
    channels_[id] = static_cast<std::size_t>(it - topics_.begin());
    return true;
  }

  bool read_summary() {
    std::vector<std::uint8_t> buf;
    const std::uint64_t footer = file_.size() - 8 - 29;
    file_.read(footer, 29, buf, "the footer");
    ByteReader f(buf, path_ + ": footer");
    if (f.get<std::uint8_t>() != kFooter) f.fail("not a footer record");
    f.get<std::uint64_t>();
    const auto summary_start = f.get<std::uint64_t>();
    if (summary_start == 0 || summary_start >= footer) return false;
    file_.read(summary_start, footer - summary_start, buf, "the summary");
    ByteReader r(buf, path_ + ": summary");
    std::map<std::uint16_t, std::uint64_t> counts;
    bool have_stats = false;
    while (!r.done()) {
      const auto op = r.get<std::uint8_t>();
      const auto len = r.get<std::uint64_t>();
      ByteReader c(r.bytes(len), path_ + ": summary record");
      if (definition(op, c) || op != kStatistics) continue;
      have_stats = true;
      c.bytes(8 + 2 + 4 + 4 + 4 + 4 + 8 + 8);
      ByteReader m(c.bytes(c.get<std::uint32_t>()), path_ + ": statistics");
      while (!m.done()) {
        const auto id = m.get<std::uint16_t>();
        counts[id] = m.get<std::uint64_t>();
      }
    }
    if (!have_stats) return false;
    for (auto [id, n] : counts)
      if (auto it = channels_.find(id); it != channels_.end()) topics_[it->second].count += n;
    return true;
  }

  // Records of one level (the file's data section or a chunk); false at DataEnd.
  bool records(ByteReader& r,
               const std::vector<std::string>& topics,
               const MessageFn* on_message,
               bool count_only) {
    while (!r.done()) {
      const auto op = r.get<std::uint8_t>();
      const auto len = r.get<std::uint64_t>();
      if (op == kDataEnd || op == kFooter) return false;
      ByteReader c(r.bytes(len), path_ + ": record");
      if (definition(op, c)) continue;
      if (op == kMessage) message(c, topics, on_message, count_only);
    }
    return true;
  }

  void message(ByteReader& c,
               const std::vector<std::string>& topics,
               const MessageFn* on_message,
               bool count_only) {
    const auto ch = c.get<std::uint16_t>();
    c.get<std::uint32_t>();
    const auto log_time = c.get<std::uint64_t>();
    c.get<std::uint64_t>();
    auto it = channels_.find(ch);
    if (it == channels_.end())
      c.fail("a message on channel " + std::to_string(ch) + " before its channel record");
    TopicInfo& t = topics_[it->second];
    if (count_only) {
      ++t.count;
      return;
    }
    if (std::find(topics.begin(), topics.end(), t.name) == topics.end()) return;
    Message m;
    m.topic = &t;
    m.log_time_ns = static_cast<std::int64_t>(log_time);
    if (it->second >= seen_.size()) seen_.resize(it->second + 1, 0);
    m.index = seen_[it->second]++;
    m.data = c.bytes(c.remaining());
    (*on_message)(m);
  }

  // One pass over the data section, chunk by chunk.
  void scan(const std::vector<std::string>& topics,
            const MessageFn* on_message,
            const ProgressFn* progress,
            bool count_only) {
    seen_.assign(topics_.size() + channels_.size() + 1, 0);
    std::uint64_t pos = 8;
    std::vector<std::uint8_t> head, rec, out;
    const std::uint64_t end = file_.size() - 8;
    while (pos < end) {
      if (progress && *progress) (*progress)(pos, file_.size());
      file_.read(pos, 9, head, "a record header");
      const std::uint8_t op = head[0];
      std::uint64_t len;
      std::memcpy(&len, head.data() + 1, 8);
      if (op == kDataEnd || op == kFooter) break;
      file_.read(pos + 9, len, rec, "a record of " + std::to_string(len) + " bytes");
      const std::string what = path_ + ": record at byte " + std::to_string(pos);
      pos += 9 + len;
      ByteReader r(rec, what);
      if (op != kChunk) {
        // A top-level record: re-read it with its opcode through records().
        std::vector<std::uint8_t> one(head);
        one.insert(one.end(), rec.begin(), rec.end());
        ByteReader single(one, what);
        if (!records(single, topics, on_message, count_only)) break;
        continue;
      }
      r.bytes(8 + 8);
      const auto size = r.get<std::uint64_t>();
      r.get<std::uint32_t>();
      const std::string compression = str(r);
      auto data = r.bytes(r.get<std::uint64_t>());
      if (compression.empty()) {
        out.assign(data.begin(), data.end());
      } else if (compression == "lz4") {
        decompress_lz4_frame(data, size, out, what);
      } else if (compression == "zstd") {
        decompress_zstd(data, size, out, what);
      } else {
        throw InputError(what + ": chunk compression '" + compression +
                         "' is not one we read (lz4, zstd)");
      }
      ByteReader inner(out, what + " (chunk)");
      records(inner, topics, on_message, count_only);
    }
    if (progress && *progress) (*progress)(file_.size(), file_.size());
  }

  FileReader file_;
  std::map<std::uint16_t, std::string> schemas_;
  std::map<std::uint16_t, std::size_t> channels_;
  std::vector<std::uint64_t> seen_;
  bool ros1_ = false;
};

}  // namespace

std::unique_ptr<Recording> open_mcap(const std::string& path) {
  return std::make_unique<Mcap>(path);
}

}  // namespace omnivert::recording
