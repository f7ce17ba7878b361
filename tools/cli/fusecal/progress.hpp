// Progress of long work on stderr: one line updated in place on a terminal, a plain line every 10%
// otherwise (logs, CI).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <string>

namespace fusecal {

class ProgressLine {
 public:
  explicit ProgressLine(std::string what) : what_(std::move(what)), tty_(isatty(STDERR_FILENO)) {}
  ~ProgressLine() {
    if (tty_ && shown_) std::fprintf(stderr, "\n");
  }
  void operator()(int done, int total) {
    const int percent = total > 0 ? done * 100 / total : 100;
    if (tty_) {
      std::fprintf(stderr, "\r%s: %d/%d (%d%%)", what_.c_str(), done, total, percent);
      shown_ = true;
    } else if (percent / 10 != last_decile_) {
      last_decile_ = percent / 10;
      std::fprintf(stderr, "%s: %d/%d (%d%%)\n", what_.c_str(), done, total, percent);
    }
  }

 private:
  std::string what_;
  bool tty_;
  bool shown_ = false;
  int last_decile_ = -1;
};

}  // namespace fusecal
