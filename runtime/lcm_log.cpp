#include "runtime/lcm_log.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace fusecal {

namespace {

constexpr uint32_t kMagic = 0xEDA1DA01;
constexpr int64_t kHeaderBytes = 28;
constexpr int64_t kMaxChannelBytes = 256;            // LCM's own limit on channel names
constexpr int64_t kMaxDataBytes = int64_t(1) << 31;  // sanity bound for corrupt lengths

uint32_t ReadU32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}
uint64_t ReadU64(const uint8_t* p) { return (uint64_t(ReadU32(p)) << 32) | ReadU32(p + 4); }
void PutU32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (24 - 8 * i));
}
void PutU64(uint8_t* p, uint64_t v) {
  PutU32(p, uint32_t(v >> 32));
  PutU32(p + 4, uint32_t(v));
}

}  // namespace

LogReader::LogReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw LogError(path + ": cannot open (" + std::strerror(errno) + ")");
  std::fseek(file_, 0, SEEK_END);
  file_size_ = std::ftell(file_);
  std::fseek(file_, 0, SEEK_SET);
  uint8_t head[4];
  if (file_size_ == 0) return;  // an empty log is a valid log with no events
  if (file_size_ < 4 || std::fread(head, 1, 4, file_) != 4 || ReadU32(head) != kMagic) {
    std::fclose(file_);
    file_ = nullptr;
    throw LogError(path + ": not an LCM event log (no LCM magic number at the start of the file)");
  }
  std::fseek(file_, 0, SEEK_SET);
}

LogReader::~LogReader() {
  if (file_) std::fclose(file_);
}

bool LogReader::Resync(int64_t from) {
  std::fseek(file_, from, SEEK_SET);
  uint32_t window = 0;
  int64_t pos = from;
  int c;
  while ((c = std::fgetc(file_)) != EOF) {
    window = (window << 8) | uint32_t(c);
    ++pos;
    if (pos - from >= 4 && window == kMagic) {
      std::fseek(file_, pos - 4, SEEK_SET);
      problems_.push_back("corrupt data at bytes " + std::to_string(from) + ".." + std::to_string(pos - 4) +
                          " skipped");
      return true;
    }
  }
  problems_.push_back("corrupt data from byte " + std::to_string(from) + " to the end of the file");
  return false;
}

std::optional<LogEvent> LogReader::Next() {
  while (file_) {
    const int64_t start = std::ftell(file_);
    uint8_t header[kHeaderBytes];
    const size_t got = std::fread(header, 1, kHeaderBytes, file_);
    if (got == 0) return std::nullopt;
    if (got < size_t(kHeaderBytes)) {
      if (got >= 4 && ReadU32(header) != kMagic) {
        if (!Resync(start + 1)) return std::nullopt;
        continue;
      }
      problems_.push_back("truncated: the last event (at byte " + std::to_string(start) + ") ends inside its header");
      return std::nullopt;
    }
    const int64_t channel_len = ReadU32(header + 20);
    const int64_t data_len = ReadU32(header + 24);
    if (ReadU32(header) != kMagic || channel_len <= 0 || channel_len > kMaxChannelBytes || data_len > kMaxDataBytes) {
      if (!Resync(start + 1)) return std::nullopt;
      continue;
    }
    const int64_t end = start + kHeaderBytes + channel_len + data_len;
    if (end > file_size_) {
      problems_.push_back("truncated: the event at byte " + std::to_string(start) + " needs " +
                          std::to_string(end - start) + " bytes, the file ends after " +
                          std::to_string(file_size_ - start));
      std::fseek(file_, 0, SEEK_END);
      return std::nullopt;
    }
    LogEvent event;
    event.event_number = int64_t(ReadU64(header + 4));
    event.utime = int64_t(ReadU64(header + 12));
    event.channel.resize(channel_len);
    event.data.resize(data_len);
    if (std::fread(event.channel.data(), 1, channel_len, file_) != size_t(channel_len) ||
        std::fread(event.data.data(), 1, data_len, file_) != size_t(data_len)) {
      problems_.push_back("read error at byte " + std::to_string(start));
      return std::nullopt;
    }
    return event;
  }
  return std::nullopt;
}

void CheckReplaceableOutput(const std::string& path) {
  struct stat info {};
  if (lstat(path.c_str(), &info) != 0) return;  // a new path
  if (S_ISREG(info.st_mode)) return;
  const char* what = S_ISDIR(info.st_mode)    ? "a directory"
                     : S_ISCHR(info.st_mode)  ? "a character device"
                     : S_ISBLK(info.st_mode)  ? "a block device"
                     : S_ISFIFO(info.st_mode) ? "a pipe"
                     : S_ISSOCK(info.st_mode) ? "a socket"
                     : S_ISLNK(info.st_mode)  ? "a symbolic link"
                                              : "not a regular file";
  throw LogError(path + " is " + what + ": the output must be a new path or a regular file, which is replaced");
}

LogWriter::LogWriter(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw LogError(path + ": cannot create (" + std::strerror(errno) + ")");
}

LogWriter::~LogWriter() {
  if (file_) std::fclose(file_);
}

void LogWriter::Write(const std::string& channel, int64_t utime, const void* data, size_t size) {
  if (!file_) throw LogError(path_ + ": log already closed");
  if (channel.empty() || int64_t(channel.size()) > kMaxChannelBytes)
    throw LogError("channel name must have 1.." + std::to_string(kMaxChannelBytes) + " bytes");
  uint8_t header[kHeaderBytes];
  PutU32(header, kMagic);
  PutU64(header + 4, uint64_t(next_event_++));
  PutU64(header + 12, uint64_t(utime));
  PutU32(header + 20, uint32_t(channel.size()));
  PutU32(header + 24, uint32_t(size));
  if (std::fwrite(header, 1, kHeaderBytes, file_) != size_t(kHeaderBytes) ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      std::fwrite(data, 1, size, file_) != size)
    throw LogError(path_ + ": write failed (" + std::strerror(errno) + ")");
}

void LogWriter::Close() {
  if (!file_) return;
  const bool flushed = std::fflush(file_) == 0;
  const bool ok = std::fclose(file_) == 0 && flushed;
  file_ = nullptr;
  if (!ok) throw LogError(path_ + ": could not flush the log (disk full?)");
}

}  // namespace fusecal
