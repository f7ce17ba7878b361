#include "tests/support/db3_test_writer.hpp"

#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace fusecal::testing {

namespace {

void Execute(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string reason = error ? error : "?";
    sqlite3_free(error);
    throw std::runtime_error("sqlite: " + reason + " in: " + sql);
  }
}

void InsertMessages(sqlite3* db, const std::vector<BagMessage>& messages) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1, &raw, nullptr) !=
      SQLITE_OK)
    throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(db));
  std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> insert(raw, sqlite3_finalize);
  for (const BagMessage& m : messages) {
    sqlite3_bind_int64(insert.get(), 1, static_cast<sqlite3_int64>(m.topic + 1));
    sqlite3_bind_int64(insert.get(), 2, m.log_time_ns);
    // An empty vector's data() may be null, which sqlite binds as NULL rather than an empty blob.
    static const uint8_t kNothing = 0;
    sqlite3_bind_blob(insert.get(), 3, m.data.empty() ? &kNothing : m.data.data(), static_cast<int>(m.data.size()),
                      SQLITE_TRANSIENT);
    if (sqlite3_step(insert.get()) != SQLITE_DONE)
      throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(db));
    sqlite3_reset(insert.get());
  }
}

}  // namespace

void WriteDb3(const std::string& path, const std::vector<BagTopic>& topics, const std::vector<BagMessage>& messages,
              const Db3WriteOptions& options) {
  std::filesystem::remove(path);
  sqlite3* raw = nullptr;
  if (sqlite3_open(path.c_str(), &raw) != SQLITE_OK) {
    sqlite3_close(raw);
    throw std::runtime_error("sqlite: cannot create " + path);
  }
  std::unique_ptr<sqlite3, int (*)(sqlite3*)> db(raw, sqlite3_close);
  if (options.topics_table) {
    Execute(db.get(),
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
            "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)");
    for (size_t t = 0; t < topics.size(); ++t)
      Execute(db.get(), "INSERT INTO topics VALUES (" + std::to_string(t + 1) + ", '" + topics[t].name + "', '" +
                            topics[t].type + "', '" + topics[t].serialization_format + "', '')");
  }
  if (!options.messages_table) return;
  Execute(db.get(),
          "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
          "timestamp INTEGER NOT NULL, data BLOB NOT NULL)");
  if (options.timestamp_index) Execute(db.get(), "CREATE INDEX timestamp_idx ON messages (timestamp ASC)");
  Execute(db.get(), "BEGIN");
  InsertMessages(db.get(), messages);
  Execute(db.get(), "COMMIT");
}

void WriteRosbag2Metadata(const std::string& folder, const std::string& storage_identifier,
                          const std::vector<std::string>& files, const std::vector<BagTopic>& topics,
                          const std::vector<BagMessage>& messages) {
  std::vector<size_t> counts(topics.size(), 0);
  for (const BagMessage& m : messages) ++counts.at(m.topic);
  std::ofstream out(folder + "/metadata.yaml");
  out << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: " << storage_identifier
      << "\n  duration:\n    nanoseconds: 0\n  starting_time:\n    nanoseconds_since_epoch: 0\n"
      << "  message_count: " << messages.size() << "\n  topics_with_message_count:\n";
  for (size_t t = 0; t < topics.size(); ++t)
    out << "    - topic_metadata:\n        name: " << topics[t].name << "\n        type: " << topics[t].type
        << "\n        serialization_format: " << topics[t].serialization_format
        << "\n        offered_qos_profiles: \"\"\n      message_count: " << counts[t] << "\n";
  out << "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n";
  for (const std::string& file : files) out << "    - " << file << "\n";
  if (!out) throw std::runtime_error("cannot write " + folder + "/metadata.yaml");
}

}  // namespace fusecal::testing
