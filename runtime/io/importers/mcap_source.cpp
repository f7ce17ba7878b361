#include "runtime/io/importers/mcap_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace fusecal::mcap {

namespace {

void CheckRange(uint64_t offset, uint64_t n, uint64_t size) {
  if (offset > size || n > size - offset)
    throw std::runtime_error("read of " + std::to_string(n) + " bytes at offset " + std::to_string(offset) +
                             " past the end (" + std::to_string(size) + " bytes)");
}

class FileSource : public ByteSource {
 public:
  explicit FileSource(const std::string& path) : path_(path) {
    // O_NONBLOCK: a FIFO named like a bag must not hang the open (it is refused below).
    fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd_ < 0) throw std::runtime_error(path + ": cannot open (" + std::strerror(errno) + ")");
    struct stat st {};
    if (fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      close(fd_);
      throw std::runtime_error(path + ": not a regular file");
    }
    size_ = static_cast<uint64_t>(st.st_size);
  }
  ~FileSource() override { close(fd_); }
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;

  uint64_t size() const override { return size_; }

  void ReadAt(uint64_t offset, uint64_t n, uint8_t* out) override {
    try {
      CheckRange(offset, n, size_);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(path_ + ": " + e.what());
    }
    uint64_t done = 0;
    while (done < n) {
      const ssize_t got = pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      // Fewer bytes than fstat promised: the file shrank while open.
      if (got <= 0)
        throw std::runtime_error(path_ + ": read failed at offset " + std::to_string(offset + done) + " (" +
                                 (got < 0 ? std::strerror(errno) : "file shorter than when opened") + ")");
      done += static_cast<uint64_t>(got);
    }
    bytes_read_ += n;
  }

 private:
  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
};

class MemoryBytes : public ByteSource {
 public:
  MemoryBytes(const uint8_t* data, size_t size) : bytes_(data, data + size) {}
  uint64_t size() const override { return bytes_.size(); }
  void ReadAt(uint64_t offset, uint64_t n, uint8_t* out) override {
    CheckRange(offset, n, bytes_.size());
    if (n > 0) std::memcpy(out, bytes_.data() + offset, n);
    bytes_read_ += n;
  }

 private:
  std::vector<uint8_t> bytes_;
};

}  // namespace

std::unique_ptr<ByteSource> OpenFileSource(const std::string& path) { return std::make_unique<FileSource>(path); }

std::unique_ptr<ByteSource> MemorySource(const uint8_t* data, size_t size) {
  return std::make_unique<MemoryBytes>(data, size);
}

}  // namespace fusecal::mcap
