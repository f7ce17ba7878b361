// LCM event logs (the standard format of lcm-logger / lcm-logplayer): a reader that reports
// truncation and garbage instead of silently stopping, and a writer.
//
// Event layout (big-endian): magic 0xEDA1DA01 (4), event number (8), utime (8), channel length (4),
// data length (4), channel bytes, data bytes.
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/channels.hpp"

namespace fusecal {

class LogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LogEvent {
  int64_t event_number = 0;
  int64_t utime = 0;
  std::string channel;
  std::vector<uint8_t> data;
};

class LogReader {
 public:
  // Throws LogError when the file cannot be opened or does not start like an LCM log.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  // The next intact event, or nullopt at the end. Corrupt stretches are skipped (resynchronising on
  // the next magic number) and truncation at the end is detected; both are recorded in problems().
  std::optional<LogEvent> Next();

  // What was wrong with the file so far, one sentence each, with byte offsets.
  const std::vector<std::string>& problems() const { return problems_; }
  const std::string& path() const { return path_; }
  int64_t file_size() const { return file_size_; }

 private:
  bool Resync(int64_t from);

  std::string path_;
  FILE* file_ = nullptr;
  int64_t file_size_ = 0;
  std::vector<std::string> problems_;
};

// A log written as PATH.partial and renamed onto PATH when complete may only replace a regular file (or
// take a new path): throws LogError naming PATH when it is a directory, a device (e.g. /dev/full), a
// socket or a pipe. Call it before writing and again before the rename.
void CheckReplaceableOutput(const std::string& path);

class LogWriter {
 public:
  // Throws LogError when the file cannot be created.
  explicit LogWriter(const std::string& path);
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  void Write(const std::string& channel, int64_t utime, const void* data, size_t size);
  template <typename M>
  void WriteMessage(const std::string& channel, int64_t utime, const M& message) {
    std::vector<uint8_t> buffer(message.getEncodedSize());
    message.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
    Write(channel, utime, buffer.data(), buffer.size());
  }
  // The same on a pipeline channel: the message type is checked at compile time.
  template <typename M>
  void WriteMessage(const Channel<M>& channel, int64_t utime, const M& message) {
    WriteMessage<M>(channel.name, utime, message);
  }
  // Flushes and closes; throws LogError if the data could not be written completely.
  void Close();
  int64_t events_written() const { return next_event_; }

 private:
  std::string path_;
  FILE* file_ = nullptr;
  int64_t next_event_ = 0;
};

}  // namespace fusecal
