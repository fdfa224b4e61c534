// rosbag2's sqlite3 storage: tables topics(id, name, type, serialization_format, ...) and
// messages(id, topic_id, timestamp, data), the data CDR-serialised (zstd-compressed each when
// the bag was recorded with compression_mode MESSAGE). SQLite steps through the rows of the
// query one at a time, so memory stays bounded.

#include <sqlite3.h>

#include <algorithm>
#include <map>

#include "recording/bytes.hpp"
#include "recording/readers.hpp"

namespace omnivert::recording {

namespace {

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::string& path) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s_, nullptr) != SQLITE_OK) {
      throw InputError(path, 0, std::string("not a rosbag2 sqlite3 file: ") + sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  sqlite3_stmt* get() { return s_; }

 private:
  sqlite3_stmt* s_ = nullptr;
};

std::string text(sqlite3_stmt* s, int col) {
  const auto* p = sqlite3_column_text(s, col);
  return p ? reinterpret_cast<const char*>(p) : "";
}

class Db3 final : public Recording {
 public:
  Db3(const std::string& path, bool message_zstd) : message_zstd_(message_zstd) {
    path_ = path;
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw InputError(path, 0, "cannot be opened as sqlite3: " + why);
    }
    try {
      Statement s(
          db_,
          "SELECT t.id, t.name, t.type, (SELECT count(*) FROM messages m WHERE m.topic_id = t.id) "
          "FROM topics t ORDER BY t.id",
          path);
      int rc;
      while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
        ids_[sqlite3_column_int64(s.get(), 0)] = topics_.size();
        topics_.push_back({text(s.get(), 1),
                           text(s.get(), 2),
                           static_cast<std::uint64_t>(sqlite3_column_int64(s.get(), 3))});
      }
      check(rc);
    } catch (...) {
      sqlite3_close(db_);
      throw;
    }
  }
  ~Db3() override { sqlite3_close(db_); }
  std::string format() const override { return "ROS 2 bag (sqlite3)"; }
  Serialization serialization() const override { return Serialization::kCdr; }

  void read(const std::vector<std::string>& topics,
            const MessageFn& on_message,
            const ProgressFn& progress) override {
    std::string in;
    std::uint64_t total = 0;
    for (const auto& [id, k] : ids_) {
      if (std::find(topics.begin(), topics.end(), topics_[k].name) == topics.end()) continue;
      if (!in.empty()) in += ',';
      in += std::to_string(id);
      total += topics_[k].count;
    }
    if (in.empty()) return;
    Statement s(db_,
                "SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN (" + in +
                    ") ORDER BY timestamp, id",
                path_);
    std::vector<std::uint64_t> seen(topics_.size(), 0);
    std::vector<std::uint8_t> plain;
    std::uint64_t done = 0;
    int rc;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      const std::size_t k = ids_.at(sqlite3_column_int64(s.get(), 0));
      const auto* blob = static_cast<const std::uint8_t*>(sqlite3_column_blob(s.get(), 2));
      std::span<const std::uint8_t> data(
          blob, static_cast<std::size_t>(sqlite3_column_bytes(s.get(), 2)));
      Message m;
      m.topic = &topics_[k];
      m.log_time_ns = sqlite3_column_int64(s.get(), 1);
      m.index = seen[k]++;
      if (message_zstd_) {
        decompress_zstd(
            data,
            0,
            plain,
            path_ + ": topic " + topics_[k].name + ", message " + std::to_string(m.index));
        data = plain;
      }
      m.data = data;
      on_message(m);
      if (progress && (++done % 64 == 0)) progress(done, total);
    }
    check(rc);
    if (progress) progress(total, total);
  }

 private:
  void check(int rc) const {
    if (rc != SQLITE_DONE)
      throw InputError(path_, 0, std::string("sqlite3: ") + sqlite3_errmsg(db_));
  }
  sqlite3* db_ = nullptr;
  bool message_zstd_ = false;
  std::map<sqlite3_int64, std::size_t> ids_;
};

}  // namespace

std::unique_ptr<Recording> open_db3(const std::string& path, bool message_zstd) {
  return std::make_unique<Db3>(path, message_zstd);
}

}  // namespace omnivert::recording
