#include "tests/support/looped_recording.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "runtime/channels.hpp"

namespace fusecal::testing {
namespace {

// Any camera's (CAMERA_IMAGE_left, ...) too.
bool IsSensorEvent(const LogEvent& event) {
  const std::string channel = PipelineChannelOf(event.channel);
  return channel == channels::kCameraInfo.name || channel == channels::kCameraImage.name ||
         channel == channels::kLidarScan.name;
}

template <typename Message>
bool Decode(const LogEvent& event, Message* message) {
  return message->decode(event.data.data(), 0, static_cast<int>(event.data.size())) >= 0;
}

template <typename Message>
void Encode(const Message& message, LogEvent* event) {
  event->data.resize(static_cast<size_t>(message.getEncodedSize()));
  message.encode(event->data.data(), 0, static_cast<int>(event->data.size()));
}

// How long after its stamp a scan's last point came (0 without point times).
double ScanSpanS(const point_cloud_t& scan) {
  if (scan.time_offset_s.empty()) return 0.0;
  return std::max(0.0, static_cast<double>(*std::max_element(scan.time_offset_s.begin(), scan.time_offset_s.end())));
}

// When the event ends: a scan at its last point.
int64_t EndUtime(const LogEvent& event) {
  point_cloud_t scan;
  if (event.channel != channels::kLidarScan.name || !Decode(event, &scan)) return event.utime;
  return event.utime + std::llround(ScanSpanS(scan) * 1e6);
}

}  // namespace

LoopedRecording::LoopedRecording(const std::string& log, double min_seconds)
    : reader_(std::make_unique<LogReader>(log)) {
  if (min_seconds <= 0) return;
  while (auto event = reader_->Next())
    if (IsSensorEvent(*event)) events_.push_back(std::move(*event));
  reader_.reset();
  if (events_.empty()) throw std::runtime_error(log + " has no CAMERA_INFO, CAMERA_IMAGE or LIDAR_SCAN event");
  first_utime_ = events_.front().utime;
  last_utime_ = first_utime_;
  end_utimes_.reserve(events_.size());
  for (const LogEvent& event : events_) {
    end_utimes_.push_back(EndUtime(event));
    last_utime_ = std::max(last_utime_, end_utimes_.back());
  }
  // Backward, an event's stamp is last_utime_ minus its end: the later it ends, the sooner it comes.
  backward_order_.resize(events_.size());
  std::iota(backward_order_.begin(), backward_order_.end(), size_t{0});
  std::stable_sort(backward_order_.begin(), backward_order_.end(),
                   [&](size_t a, size_t b) { return end_utimes_[a] > end_utimes_[b]; });
  // Each pass starts where the last one ended: at a turn the frames keep their spacing (a gap would read
  // as lost frames).
  const double pass_s = std::max(1e-6, pass_seconds());
  passes_ = std::max(1, static_cast<int>(std::ceil(min_seconds / pass_s - 1e-9)));
}

std::optional<LogEvent> LoopedRecording::NextStreamed() {
  while (auto event = reader_->Next())
    if (IsSensorEvent(*event)) return event;
  return std::nullopt;
}

std::optional<LogEvent> LoopedRecording::Next() {
  std::optional<LogEvent> event = NextEvent();
  if (event && event->channel == channels::kCameraImage.name) image_gaps_.Add(event->utime);
  if (event && event->channel == channels::kLidarScan.name) scan_gaps_.Add(event->utime);
  return event;
}

std::optional<LogEvent> LoopedRecording::NextEvent() {
  if (reader_) return NextStreamed();
  if (next_ == events_.size()) {
    next_ = 0;
    ++pass_;
  }
  if (pass_ >= passes_) return std::nullopt;
  const bool backward = pass_ % 2 == 1;
  const int64_t base = first_utime_ + pass_ * (last_utime_ - first_utime_);
  const size_t index = backward ? backward_order_[next_] : next_;
  ++next_;
  return Restamped(index, backward, base);
}

// Forward, an event keeps its place in the pass; backward, time runs from the recording's end, so a scan
// is stamped at its last point and its points' times count back from there.
LogEvent LoopedRecording::Restamped(size_t index, bool backward, int64_t base) const {
  LogEvent event = events_[index];
  const int64_t utime = backward ? base + (last_utime_ - end_utimes_[index]) : base + (event.utime - first_utime_);
  event.utime = utime;
  if (event.channel == channels::kLidarScan.name) {
    point_cloud_t scan;
    if (!Decode(event, &scan)) return event;
    if (backward) {
      const auto span_s = static_cast<float>(ScanSpanS(scan));
      for (float& t : scan.time_offset_s) t = span_s - t;
    }
    scan.utime = utime;
    Encode(scan, &event);
  } else if (PipelineChannelOf(event.channel) == channels::kCameraImage.name) {
    image_t image;
    if (!Decode(event, &image)) return event;
    image.utime = utime;
    Encode(image, &event);
  } else {
    camera_info_t info;
    if (!Decode(event, &info)) return event;
    info.utime = utime;
    Encode(info, &event);
  }
  return event;
}

}  // namespace fusecal::testing
