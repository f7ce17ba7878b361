// A sqlite3 file (.db3) as one file of a rosbag2 bag (rosbag2_storage.hpp), through libsqlite3, opened
// read-only. rosbag2's schema: topics(id, name, type, serialization_format, offered_qos_profiles, ...) and
// messages(id, topic_id, timestamp, data), with an index on timestamp.
#include <sqlite3.h>

#include <filesystem>
#include <map>
#include <stdexcept>

#include "runtime/io/importers/rosbag2_storage.hpp"

namespace fusecal::rosbag2_detail {

namespace {

using Statement = std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)>;

class Db3Cursor : public MessageCursor {
 public:
  Db3Cursor(const std::string& path, sqlite3* db, Statement statement, const std::map<int64_t, size_t>& topic_of_id,
            uint64_t& bytes_read)
      : path_(path), db_(db), statement_(std::move(statement)), topic_of_id_(topic_of_id), bytes_read_(bytes_read) {}

  bool Next(StoredMessage& message) override {
    const int rc = sqlite3_step(statement_.get());
    if (rc == SQLITE_DONE) return false;
    if (rc != SQLITE_ROW) throw std::runtime_error(path_ + ": reading messages: " + sqlite3_errmsg(db_));
    const int64_t topic_id = sqlite3_column_int64(statement_.get(), 0);
    const auto topic = topic_of_id_.find(topic_id);
    if (topic == topic_of_id_.end())
      throw std::runtime_error(path_ + ": a message of topic_id " + std::to_string(topic_id) +
                               ", which the topics table does not list");
    message.topic = topic->second;
    message.log_time_ns = sqlite3_column_int64(statement_.get(), 1);
    message.data = static_cast<const uint8_t*>(sqlite3_column_blob(statement_.get(), 2));
    message.size = static_cast<size_t>(sqlite3_column_bytes(statement_.get(), 2));
    bytes_read_ += message.size;
    return true;
  }

 private:
  const std::string& path_;
  sqlite3* db_;
  Statement statement_;
  const std::map<int64_t, size_t>& topic_of_id_;
  uint64_t& bytes_read_;
};

class Db3Storage : public StorageFile {
 public:
  Db3Storage(const std::string& path, bool count_messages) : path_(path) {
    if (!std::filesystem::is_regular_file(path)) throw std::runtime_error(path + ": no such file");
    const int rc = sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr);
    if (rc != SQLITE_OK) {
      const std::string reason = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
      sqlite3_close(db_);
      throw std::runtime_error(path + ": cannot open as sqlite3 (" + reason + ")");
    }
    sqlite3_busy_timeout(db_, 2000);  // a recorder may still hold a lock
    try {
      ReadTopics();
      Prepare("SELECT topic_id, timestamp, data FROM messages WHERE 0");  // the columns are there
      if (count_messages) CountMessages();
    } catch (...) {
      sqlite3_close(db_);
      throw;
    }
  }
  ~Db3Storage() override { sqlite3_close(db_); }
  Db3Storage(const Db3Storage&) = delete;
  Db3Storage& operator=(const Db3Storage&) = delete;

  const std::vector<StoredTopic>& topics() const override { return topics_; }
  std::vector<std::string> warnings() const override { return {}; }
  uint64_t bytes_read() const override { return bytes_read_; }

  std::unique_ptr<MessageCursor> Messages(const std::vector<bool>& selected) override {
    std::string ids;
    for (const auto& [id, topic] : topic_of_id_)
      if (selected.at(topic)) ids += (ids.empty() ? "" : ",") + std::to_string(id);
    // The rowid after the timestamp keeps the recording order among equal stamps, and rosbag2's index on
    // timestamp (which holds the rowid) serves both without a sort.
    std::string sql =
        "SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN (" + ids + ") ORDER BY timestamp, id";
    return std::make_unique<Db3Cursor>(path_, db_, Prepare(sql), topic_of_id_, bytes_read_);
  }

 private:
  Statement Prepare(const std::string& sql) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK)
      throw std::runtime_error(path_ + ": not a rosbag2 sqlite3 bag (" + sqlite3_errmsg(db_) + ")");
    return Statement(statement, sqlite3_finalize);
  }

  void ReadTopics() {
    Statement statement = Prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id");
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(statement.get())) == SQLITE_ROW) {
      const auto text = [&](int column) {
        const unsigned char* value = sqlite3_column_text(statement.get(), column);
        return value ? std::string(reinterpret_cast<const char*>(value)) : std::string();
      };
      topic_of_id_[sqlite3_column_int64(statement.get(), 0)] = topics_.size();
      topics_.push_back({text(1), text(2), text(3), 0});
    }
    if (rc != SQLITE_DONE) throw std::runtime_error(path_ + ": reading topics: " + sqlite3_errmsg(db_));
  }

  void CountMessages() {
    Statement statement = Prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id");
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(statement.get())) == SQLITE_ROW) {
      const auto topic = topic_of_id_.find(sqlite3_column_int64(statement.get(), 0));
      if (topic != topic_of_id_.end())
        topics_[topic->second].message_count = static_cast<uint64_t>(sqlite3_column_int64(statement.get(), 1));
    }
    if (rc != SQLITE_DONE) throw std::runtime_error(path_ + ": counting messages: " + sqlite3_errmsg(db_));
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::vector<StoredTopic> topics_;
  std::map<int64_t, size_t> topic_of_id_;  // topics.id: index into topics_
  uint64_t bytes_read_ = 0;
};

}  // namespace

std::unique_ptr<StorageFile> OpenDb3Storage(const std::string& path, bool count_messages) {
  return std::make_unique<Db3Storage>(path, count_messages);
}

}  // namespace fusecal::rosbag2_detail
