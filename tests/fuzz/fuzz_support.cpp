#include "fuzz_support.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

namespace fusecal::fuzz {

namespace {

// Created on first use, removed with everything in it when the process exits normally.
class ScratchDirectory {
 public:
  ScratchDirectory() {
    const char* tmp = std::getenv("TMPDIR");
    path_ = std::string(tmp && *tmp ? tmp : "/tmp") + "/fusecal-fuzz-" + std::to_string(getpid());
    std::filesystem::create_directories(path_);
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

const ScratchDirectory& Scratch() {
  static const ScratchDirectory directory;
  return directory;
}

}  // namespace

std::string ScratchFolder() { return Scratch().path(); }

std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = Scratch().path() + "/" + name;
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (fd < 0) std::abort();  // not the input's fault: stop the run rather than fuzz nothing
  size_t written = 0;
  while (written < size) {
    const ssize_t n = write(fd, data + written, size - written);
    if (n <= 0) std::abort();
    written += static_cast<size_t>(n);
  }
  close(fd);
  return path;
}

}  // namespace fusecal::fuzz
