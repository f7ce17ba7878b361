#include "stages/stationarity/stationarity_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace fusecal {

namespace {

int64_t ToMicros(double seconds) { return std::llround(seconds * 1e6); }

std::string Format(const char* fmt, double a, double b = 0) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), fmt, a, b);
  return buf;
}

std::string UtimeText(const char* sensor, int64_t utime) {
  return std::string(sensor) + " at utime " + std::to_string(utime);
}

// Keeps the newest `keep` elements.
template <typename T>
void KeepNewest(std::deque<T>* buffer, size_t keep) {
  while (buffer->size() > keep) buffer->pop_front();
}

}  // namespace

const char* ToString(StationarityPhase phase) {
  switch (phase) {
    case StationarityPhase::kMoving:
      return "moving";
    case StationarityPhase::kSettling:
      return "settling";
    case StationarityPhase::kStill:
      return "still";
  }
  return "?";
}

StationarityDetector::StationarityDetector(const StationaritySettings& settings) : settings_(settings) {
  const std::string problem = settings_.Validate();
  if (!problem.empty()) throw std::invalid_argument("stationarity settings: " + problem);
}

bool StationarityDetector::AcceptTime(const char* sensor, int64_t utime, const Run& run, int64_t* duplicates,
                                      int64_t* out_of_order) {
  if (!run.seen || utime > run.last_utime) return true;
  if (utime == run.last_utime) {
    ++*duplicates;
    Reject(UtimeText(sensor, utime) + ": duplicate timestamp, ignored");
  } else {
    ++*out_of_order;
    Reject(UtimeText(sensor, utime) + ": out of order (" + std::to_string(run.last_utime - utime) +
           " us before the previous), ignored");
  }
  return false;
}

std::vector<DetectedStation> StationarityDetector::AddImage(int64_t utime, const cv::Mat& image) {
  if (!IsSupportedImage(image)) return AddImage(utime, image, nullptr);
  // A private copy: the caller may reuse its buffer.
  return AddImage(utime, image, [copy = image.clone()] { return copy; });
}

std::vector<DetectedStation> StationarityDetector::AddImage(int64_t utime, const cv::Mat& image,
                                                            StationImage station_image) {
  ++counters_.images_received;
  if (!IsSupportedImage(image) || !station_image) {
    ++counters_.images_invalid;
    Reject(UtimeText("image", utime) + ": empty or not an 8-bit grey/BGR image, ignored");
    return {};
  }
  if (!AcceptTime("image", utime, camera_, &counters_.images_duplicate, &counters_.images_out_of_order)) return {};
  ++counters_.images_used;

  const bool gap = camera_.seen && utime - camera_.last_utime > ToMicros(settings_.max_frame_gap_s);
  if (gap) ++counters_.image_gaps;
  const double gap_s = camera_.seen ? (utime - camera_.last_utime) * 1e-6 : 0.0;
  if (!camera_.seen) camera_.first_utime = utime;
  camera_.seen = true;
  camera_.last_utime = utime;

  auto frame = std::make_shared<const ImageFrame>(PrepareImage(utime, image, settings_.image));
  if (!frame->textured) {
    // Black, blank or featureless frame: stillness cannot be decided, and it cannot be a station image.
    ++counters_.images_without_texture;
    camera_.still = false;
    camera_.reason = "image without texture (contrast " + Format("%.1f", frame->contrast) + ", " +
                     std::to_string(frame->corners.size()) + " corners)";
    prev_image_.reset();
    anchor_image_.reset();
    images_.clear();
    image_flow_px_ = image_drift_px_ = NAN;
    image_tracks_ = 0;
  } else if (!prev_image_ || gap) {
    camera_.still = false;
    camera_.reason = gap ? Format("gap of %.2f s between images", gap_s) : "first image of a run";
    prev_image_ = anchor_image_ = frame;
    images_.clear();
    images_.push_back({utime, std::move(station_image), frame});
    image_flow_px_ = image_drift_px_ = NAN;
    image_tracks_ = 0;
  } else {
    JudgeImageMotion(utime, station_image, frame);
  }
  Prune();
  return Evaluate(false);
}

// A textured frame following the previous one without a gap: still when the flow from the previous frame and
// the drift from the anchor are small, else it becomes the anchor of a new run (camera_.reason says why).
void StationarityDetector::JudgeImageMotion(int64_t utime, const StationImage& image,
                                            const std::shared_ptr<const ImageFrame>& frame) {
  const ImageMotionSettings& is = settings_.image;
  const ImageFlow flow = MeasureFlow(*prev_image_, *frame, is);
  // The drift only decides when the flow says still (half the tracking while the rig moves).
  const bool flow_still = flow.usable() && flow.median_px <= is.still_flow_px;
  ImageFlow drift = flow;
  if (anchor_image_ != prev_image_) {
    if (flow_still) {
      drift = MeasureFlow(*anchor_image_, *frame, is);
    } else {
      drift.failure_reason = {ImageFlowFailure::kNotMeasured, "not measured while the rig moves"};
    }
  }
  image_flow_px_ = flow.usable() ? flow.median_px : NAN;
  image_drift_px_ = drift.usable() ? drift.median_px : NAN;
  image_tracks_ = flow.tracks;
  if (!flow.usable() || (flow_still && !drift.usable())) ++counters_.images_untracked;
  const bool still = flow_still && drift.usable() && drift.median_px <= is.max_drift_px;
  if (still) {
    if (!camera_.still) {
      camera_.still = true;
      camera_.still_since = anchor_image_->utime;
    }
    camera_.reason.clear();
    images_.push_back({utime, image, frame});
  } else {
    camera_.still = false;
    if (!flow.usable())
      camera_.reason = "image " + flow.failure_reason.text;
    else if (flow.median_px > is.still_flow_px)
      camera_.reason = Format("image flow %.3f px > %.3f px", flow.median_px, is.still_flow_px);
    else if (!drift.usable())
      camera_.reason = "image, from the anchor: " + drift.failure_reason.text;
    else
      camera_.reason = Format("image drift %.3f px > %.3f px since the run began", drift.median_px, is.max_drift_px);
    anchor_image_ = frame;
    images_.clear();
    images_.push_back({utime, image, frame});
  }
  prev_image_ = frame;
}

std::vector<DetectedStation> StationarityDetector::AddScan(int64_t utime, const PointCloud& cloud) {
  ++counters_.scans_received;
  if (!AcceptTime("scan", utime, lidar_, &counters_.scans_duplicate, &counters_.scans_out_of_order)) return {};
  auto range = std::make_shared<const RangeImage>(BuildRangeImage(cloud, settings_.lidar));
  if (range->valid_cells < settings_.lidar.min_valid_cells) {
    ++counters_.scans_empty;
    Reject(UtimeText("scan", utime) + ": " + std::to_string(range->valid_points) + " of " +
           std::to_string(cloud.size()) + " points valid (finite, in range), " + std::to_string(range->valid_cells) +
           " cells; ignored as empty");
    return {};
  }
  ++counters_.scans_used;

  const bool gap = lidar_.seen && utime - lidar_.last_utime > ToMicros(settings_.max_frame_gap_s);
  if (gap) ++counters_.scan_gaps;
  const double gap_s = lidar_.seen ? (utime - lidar_.last_utime) * 1e-6 : 0.0;
  if (!lidar_.seen) lidar_.first_utime = utime;
  lidar_.seen = true;
  lidar_.last_utime = utime;

  BufferedScan buffered{utime, std::make_shared<const PointCloud>(cloud), range};
  if (!prev_range_ || gap) {
    lidar_.still = false;
    lidar_.reason = gap ? Format("gap of %.2f s between scans", gap_s) : "first scan of a run";
    prev_range_ = anchor_range_ = range;
    anchor_scan_utime_ = utime;
    scans_.clear();
    scans_.push_back(std::move(buffered));
    lidar_change_m_ = lidar_drift_m_ = NAN;
    lidar_common_cells_ = 0;
  } else {
    const LidarChange change = CompareRangeImages(*prev_range_, *range, settings_.lidar);
    const LidarChange drift =
        anchor_range_ == prev_range_ ? change : CompareRangeImages(*anchor_range_, *range, settings_.lidar);
    lidar_change_m_ = change.usable() ? change.change_m : NAN;
    lidar_drift_m_ = drift.usable() ? drift.change_m : NAN;
    lidar_common_cells_ = change.common_cells;
    const LidarChangeSettings& ls = settings_.lidar;
    if (change.usable() && drift.usable() && change.change_m <= ls.still_change_m && drift.change_m <= ls.max_drift_m) {
      if (!lidar_.still) {
        lidar_.still = true;
        lidar_.still_since = anchor_scan_utime_;
      }
      lidar_.reason.clear();
      scans_.push_back(std::move(buffered));
    } else {
      lidar_.still = false;
      if (!change.usable())
        lidar_.reason = "lidar " + change.failure_reason.text;
      else if (change.change_m > ls.still_change_m)
        lidar_.reason = Format("lidar change %.4f m > %.4f m", change.change_m, ls.still_change_m);
      else if (!drift.usable())
        lidar_.reason = "lidar, from the anchor: " + drift.failure_reason.text;
      else
        lidar_.reason = Format("lidar drift %.4f m > %.4f m since the run began", drift.change_m, ls.max_drift_m);
      anchor_range_ = range;
      anchor_scan_utime_ = utime;
      scans_.clear();
      scans_.push_back(std::move(buffered));
    }
    prev_range_ = range;
  }
  Prune();
  return Evaluate(false);
}

void StationarityDetector::Prune() {
  // A frame older than the other sensor's (current or next) still run start can never be in a still
  // interval: the combined run starts at the later of the two runs' starts.
  if (lidar_.seen) {
    const int64_t bound = lidar_.still ? lidar_.still_since : lidar_.last_utime;
    while (images_.size() > 1 && images_.front().utime < bound) images_.pop_front();
  }
  if (camera_.seen) {
    const int64_t bound = camera_.still ? camera_.still_since : camera_.last_utime;
    while (scans_.size() > 1 && scans_.front().utime < bound) scans_.pop_front();
  }
  // The current run has had its station (or was the same place): nothing in it is needed any more.
  if (run_active_ && run_handled_) {
    KeepNewest(&images_, 1);
    KeepNewest(&scans_, 1);
  }
  const size_t cap = static_cast<size_t>(settings_.max_buffered_frames);
  KeepNewest(&images_, cap);
  KeepNewest(&scans_, cap);
}

std::vector<DetectedStation> StationarityDetector::Evaluate(bool flushing) {
  std::vector<DetectedStation> out;
  // Streams further apart than sensor_timeout_s (a sensor stalled, or clocks offset): no common interval
  // can be trusted.
  const bool in_step = std::llabs(camera_.last_utime - lidar_.last_utime) <= ToMicros(settings_.sensor_timeout_s);
  if (!(camera_.still && lidar_.still && in_step)) {
    run_active_ = false;
    run_handled_ = false;
    return out;
  }
  const int64_t from = std::max(camera_.still_since, lidar_.still_since);
  const int64_t to =
      flushing ? std::max(camera_.last_utime, lidar_.last_utime) : std::min(camera_.last_utime, lidar_.last_utime);
  if (!run_active_ || from != run_from_) {
    run_active_ = true;
    run_from_ = from;
    run_handled_ = false;
    run_unpaired_counted_ = false;
    run_outcome_.clear();
  }
  if (run_handled_ || to - from < ToMicros(settings_.min_still_s)) return out;
  if (auto station = TryEmit(from, to)) out.push_back(std::move(*station));
  return out;
}

std::optional<DetectedStation> StationarityDetector::TryEmit(int64_t from, int64_t to) {
  // The pair closest in time inside [from, to]; among those within pair_tie_s of the closest, the latest
  // (furthest from the motion that ended the previous run).
  const int64_t max_dt = ToMicros(settings_.max_pair_dt_s), tie = ToMicros(settings_.pair_tie_s);
  const int64_t best_dt = ClosestPairDt(from, to);
  if (best_dt > max_dt) {
    if (!run_unpaired_counted_) {
      ++counters_.still_runs_unpaired;
      run_unpaired_counted_ = true;
    }
    run_outcome_ =
        "still, but no image and scan within " + Format("%.3f s", settings_.max_pair_dt_s) + " of each other yet";
    return std::nullopt;
  }
  const auto [best_image, best_scan] = LatestPairNearClosest(from, to, best_dt, tie);

  if (reference_ && !MovedSinceLastStation(*best_image, *best_scan)) {
    ++counters_.stations_same_place;
    MarkRunHandled("still at the place of station " + std::to_string(next_id_ - 1) + " (the rig has not moved since)");
    return std::nullopt;
  }

  DetectedStation s = BuildStation(*best_image, *best_scan, from, to);
  reference_ = Reference{best_image->frame, best_scan->range};
  ++counters_.stations_emitted;
  MarkRunHandled("still, station " + std::to_string(s.id) + " emitted");
  return s;
}

// The smallest |image utime - scan utime| over the buffered pairs inside [from, to] (int64 max when none).
int64_t StationarityDetector::ClosestPairDt(int64_t from, int64_t to) const {
  int64_t best_dt = std::numeric_limits<int64_t>::max();
  for (const auto& im : images_) {
    if (im.utime < from || im.utime > to) continue;
    for (const auto& sc : scans_) {
      if (sc.utime < from || sc.utime > to) continue;
      best_dt = std::min(best_dt, std::abs(im.utime - sc.utime));
    }
  }
  return best_dt;
}

// Among the pairs inside [from, to] at most best_dt + tie apart, the latest (ties: the closer in time).
std::pair<const StationarityDetector::BufferedImage*, const StationarityDetector::BufferedScan*>
StationarityDetector::LatestPairNearClosest(int64_t from, int64_t to, int64_t best_dt, int64_t tie) const {
  const BufferedImage* best_image = nullptr;
  const BufferedScan* best_scan = nullptr;
  int64_t best_later = std::numeric_limits<int64_t>::min(), chosen_dt = 0;
  for (const auto& im : images_) {
    if (im.utime < from || im.utime > to) continue;
    for (const auto& sc : scans_) {
      if (sc.utime < from || sc.utime > to) continue;
      const int64_t dt = std::abs(im.utime - sc.utime);
      if (dt > best_dt + tie) continue;
      const int64_t later = std::max(im.utime, sc.utime);
      if (later > best_later || (later == best_later && dt < chosen_dt)) {
        best_later = later;
        chosen_dt = dt;
        best_image = &im;
        best_scan = &sc;
      }
    }
  }
  return {best_image, best_scan};
}

// The station of the chosen pair (takes the next id): times, image, merged cloud, drift since the anchors.
DetectedStation StationarityDetector::BuildStation(const BufferedImage& best_image, const BufferedScan& best_scan,
                                                   int64_t from, int64_t to) {
  DetectedStation s;
  s.id = next_id_++;
  s.image_utime = best_image.utime;
  s.scan_utime = best_scan.utime;
  s.utime = std::max(s.image_utime, s.scan_utime);
  s.still_from = from;
  s.still_to = to;
  s.image = best_image.image();  // a private copy (or the full decode) of the chosen frame

  const std::vector<const BufferedScan*> merged = ScansToMerge(best_scan, from);
  MergeScanClouds(merged, best_scan, &s.cloud);
  for (const BufferedScan* m : merged) s.merged_scan_utimes.push_back(m->utime);

  s.image_drift_px = NAN;
  if (anchor_image_) {
    const ImageFlow drift = MeasureFlow(*anchor_image_, *best_image.frame, settings_.image);
    if (drift.usable()) s.image_drift_px = drift.median_px;
  }
  s.lidar_change_m = NAN;
  if (anchor_range_) {
    const LidarChange change = CompareRangeImages(*anchor_range_, *best_scan.range, settings_.lidar);
    if (change.usable()) s.lidar_change_m = change.change_m;
  }
  return s;
}

// The chosen scan and the still scans just before it, oldest first: merge_scans of them when the scans
// have beams; when they do not (a non-repetitive LiDAR, whose coverage fills in over time), those of the
// last accumulate_s seconds of the still run, up to max_station_points points.
std::vector<const StationarityDetector::BufferedScan*> StationarityDetector::ScansToMerge(const BufferedScan& best_scan,
                                                                                          int64_t from) const {
  const bool accumulate = !best_scan.range->by_ring && settings_.accumulate_s > 0;
  const int64_t earliest =
      accumulate ? std::max(from, best_scan.utime - static_cast<int64_t>(settings_.accumulate_s * 1e6)) : from;
  std::vector<const BufferedScan*> merged;
  size_t points = 0;
  for (auto it = scans_.rbegin(); it != scans_.rend(); ++it) {
    if (it->utime > best_scan.utime || it->utime < earliest) continue;
    if (!accumulate && static_cast<int>(merged.size()) >= settings_.merge_scans) break;
    if (accumulate && !merged.empty() && points + it->cloud->size() > settings_.max_station_points) break;
    merged.push_back(&*it);
    points += it->cloud->size();
  }
  std::reverse(merged.begin(), merged.end());
  return merged;
}

// The clouds of `merged` (oldest first) concatenated into *cloud; intensity, ring and time offsets only when
// every merged cloud has them. A single scan is copied as it is.
void StationarityDetector::MergeScanClouds(const std::vector<const BufferedScan*>& merged,
                                           const BufferedScan& best_scan, PointCloud* cloud) {
  if (merged.size() == 1) {
    *cloud = *best_scan.cloud;
    return;
  }
  size_t total = 0;
  bool intensity = true, ring = true, time = true;
  for (const BufferedScan* m : merged) {
    const PointCloud& c = *m->cloud;
    total += c.size();
    intensity = intensity && c.intensity.size() == c.size();
    ring = ring && c.ring.size() == c.size();
    time = time && c.time_offset_s.size() == c.size();
  }
  cloud->points.reserve(total);
  for (const BufferedScan* m : merged) {
    const PointCloud& c = *m->cloud;
    cloud->points.insert(cloud->points.end(), c.points.begin(), c.points.end());
    if (intensity) cloud->intensity.insert(cloud->intensity.end(), c.intensity.begin(), c.intensity.end());
    if (ring) cloud->ring.insert(cloud->ring.end(), c.ring.begin(), c.ring.end());
    if (time) {
      // time_offset_s is relative to the station's scan time.
      const float shift = static_cast<float>((m->utime - best_scan.utime) * 1e-6);
      for (float t : c.time_offset_s) cloud->time_offset_s.push_back(t + shift);
    }
  }
}

// The current run is done (emitted or suppressed): records the outcome and drops its buffered frames.
void StationarityDetector::MarkRunHandled(const std::string& outcome) {
  run_handled_ = true;
  run_outcome_ = outcome;
  KeepNewest(&images_, 1);
  KeepNewest(&scans_, 1);
}

bool StationarityDetector::MovedSinceLastStation(const BufferedImage& image, const BufferedScan& scan) const {
  const ImageFlow flow = MeasureFlow(*reference_->frame, *image.frame, settings_.image);
  if (!flow.usable() || flow.median_px > settings_.moved_flow_px) return true;  // lost tracks: moved far
  const LidarChange change = CompareRangeImages(*reference_->range, *scan.range, settings_.lidar);
  return !change.usable() || change.change_m > settings_.moved_change_m;
}

std::optional<DetectedStation> StationarityDetector::Flush() {
  std::vector<DetectedStation> out = Evaluate(true);
  camera_ = Run();
  lidar_ = Run();
  prev_image_.reset();
  anchor_image_.reset();
  prev_range_.reset();
  anchor_range_.reset();
  images_.clear();
  scans_.clear();
  image_flow_px_ = image_drift_px_ = lidar_change_m_ = lidar_drift_m_ = NAN;
  image_tracks_ = lidar_common_cells_ = 0;
  run_active_ = run_handled_ = run_unpaired_counted_ = false;
  run_outcome_.clear();
  if (out.empty()) return std::nullopt;
  return std::move(out.front());
}

StationarityState StationarityDetector::State() const {
  StationarityState s;
  s.image_still = camera_.still;
  s.lidar_still = lidar_.still;
  s.image_flow_px = image_flow_px_;
  s.image_drift_px = image_drift_px_;
  s.image_tracks = image_tracks_;
  s.lidar_change_m = lidar_change_m_;
  s.lidar_drift_m = lidar_drift_m_;
  s.lidar_common_cells = lidar_common_cells_;
  s.last_image_utime = camera_.seen ? camera_.last_utime : 0;
  s.last_scan_utime = lidar_.seen ? lidar_.last_utime : 0;
  s.next_station_id = next_id_;
  s.counters = counters_;
  s.last_rejection = last_rejection_;

  const int64_t timeout = ToMicros(settings_.sensor_timeout_s);
  auto missing = [timeout](const Run& self, const Run& other) {
    if (!other.seen) return false;
    return self.seen ? other.last_utime - self.last_utime > timeout : other.last_utime - other.first_utime > timeout;
  };
  s.camera_missing = missing(camera_, lidar_);
  s.lidar_missing = missing(lidar_, camera_);

  if (s.camera_missing || s.lidar_missing) {
    s.phase = StationarityPhase::kMoving;
    const Run& self = s.camera_missing ? camera_ : lidar_;
    const Run& other = s.camera_missing ? lidar_ : camera_;
    const char* what = s.camera_missing ? "camera images" : "LiDAR scans";
    s.reason =
        std::string("no ") + what +
        (self.seen ? Format(" for %.1f s", (other.last_utime - self.last_utime) * 1e-6)
                   : Format(" in %.1f s of the other sensor's data", (other.last_utime - other.first_utime) * 1e-6));
    return s;
  }
  if (!camera_.still || !lidar_.still) {
    s.phase = StationarityPhase::kMoving;
    if (!camera_.seen && !lidar_.seen)
      s.reason = "no data yet";
    else if (!camera_.still)
      s.reason = camera_.seen ? camera_.reason : "no camera image yet";
    else
      s.reason = lidar_.seen ? lidar_.reason : "no LiDAR scan yet";
    return s;
  }
  const int64_t from = std::max(camera_.still_since, lidar_.still_since);
  const int64_t to = std::min(camera_.last_utime, lidar_.last_utime);
  s.still_from_utime = from;
  s.still_for_s = std::max<int64_t>(0, to - from) * 1e-6;
  if (run_handled_ || s.still_for_s >= settings_.min_still_s) {
    s.phase = StationarityPhase::kStill;
    s.reason = run_outcome_;
  } else {
    s.phase = StationarityPhase::kSettling;
    s.reason = Format("still for %.2f of %.2f s", s.still_for_s, settings_.min_still_s);
  }
  return s;
}

}  // namespace fusecal
