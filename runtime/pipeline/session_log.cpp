#include "runtime/pipeline/session_log.hpp"

#include <filesystem>
#include <system_error>

#include "runtime/channels.hpp"

namespace fusecal {

namespace {

bool IsRawFrame(const std::string& channel) {
  const std::string base = PipelineChannelOf(channel);
  return base == channels::kCameraImage.name || base == channels::kLidarScan.name;
}

// Bytes an event takes in an LCM log: sync word, event number, utime, channel and data lengths.
double EventBytes(const std::string& channel, size_t size) { return 28.0 + channel.size() + size; }

}  // namespace

SessionLog::SessionLog(const std::string& dir, const RecordSettings& settings) : settings_(settings), dir_(dir) {
  if (settings_.what != "none") session_ = std::make_unique<LogWriter>(dir + "/session.lcmlog");
}

void SessionLog::Write(const std::string& channel, int64_t utime, const uint8_t* data, size_t size,
                       const CameraInfos& camera_infos) {
  if (!session_) return;
  if (!IsRawFrame(channel)) {
    session_->Write(channel, utime, data, size);
    return;
  }
  if (settings_.what != "all") return;
  const double segment_cap = settings_.max_raw_mb * 1e6 / 8;
  if (!segment_ || segments_.back().bytes + EventBytes(channel, size) > segment_cap) StartSegment(utime, camera_infos);
  segment_->Write(channel, utime, data, size);
  segments_.back().bytes += EventBytes(channel, size);
}

void SessionLog::StartSegment(int64_t utime, const CameraInfos& camera_infos) {
  if (segment_) segment_->Close();
  std::filesystem::create_directories(dir_ + "/raw");
  segments_.push_back({dir_ + "/raw/raw-" + std::to_string(next_segment_++) + ".lcmlog", 0.0});
  segment_ = std::make_unique<LogWriter>(segments_.back().path);
  for (const auto& [channel, camera_info] : camera_infos) {
    segment_->Write(channel, utime, camera_info.data(), camera_info.size());
    segments_.back().bytes += EventBytes(channel, camera_info.size());
  }
  double total = 0;
  for (const auto& s : segments_) total += s.bytes;
  // The segment just started stays, whatever the cap: it is the only one being written.
  while (segments_.size() > 1 && total + settings_.max_raw_mb * 1e6 / 8 > settings_.max_raw_mb * 1e6) {
    std::error_code ignored;
    std::filesystem::remove(segments_.front().path, ignored);
    total -= segments_.front().bytes;
    segments_.pop_front();
    ++segments_deleted_;
  }
}

void SessionLog::Close() {
  if (segment_) segment_->Close();
  if (session_) session_->Close();
}

}  // namespace fusecal
