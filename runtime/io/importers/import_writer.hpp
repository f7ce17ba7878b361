// Writes an imported dataset as a standard LCM log. The log is written to "<path>.partial" and renamed
// to <path> only when Commit() is called, so a failed import never leaves a log that looks complete.
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "runtime/lcm_log.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

struct ImportReport {
  int images = 0;
  int scans = 0;
  int stations = 0;
  std::vector<std::string> warnings;  // files skipped and why
};

using ImportProgress = std::function<void(int done, int total)>;

class ImportWriter {
 public:
  explicit ImportWriter(const std::string& path);
  ~ImportWriter();  // removes the partial file unless committed

  // Camera model and reference extrinsic (GROUND_TRUTH, source says where it came from).
  void WriteCalibration(int64_t utime, const CameraParams& camera, const Isometry3* T_camera_lidar,
                        const std::string& source, const std::vector<std::pair<int, Isometry3>>& poses = {});
  // An image file's bytes (png or jpeg) without re-encoding.
  void WriteImageFile(int64_t utime, const std::vector<uint8_t>& bytes, const std::string& encoding, int width,
                      int height);
  // A decoded 8-bit image (grey or BGR), stored raw as mono8 or bgr8.
  void WriteImage(int64_t utime, const cv::Mat& image);
  void WriteScan(int64_t utime, const PointCloud& cloud);
  void WriteStation(int id, int64_t utime, const cv::Mat& image, const PointCloud& cloud, const CameraParams& camera);
  void Commit();

  ImportReport& report() { return report_; }

 private:
  std::string path_, partial_;
  std::unique_ptr<LogWriter> writer_;
  bool committed_ = false;
  ImportReport report_;
};

// Reads a whole file; throws std::runtime_error naming it when it cannot.
std::vector<uint8_t> ReadFileBytes(const std::string& path);

// Files in `dir` with one of `extensions` (lower case, with dot), sorted by name.
std::vector<std::string> ListFiles(const std::string& dir, const std::vector<std::string>& extensions);

}  // namespace fusecal
