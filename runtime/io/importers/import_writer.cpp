#include "runtime/io/importers/import_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "fusecal/ground_truth_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"

namespace fusecal {

namespace fs = std::filesystem;

// The output is checked before anything is written, and again before the rename.
ImportWriter::ImportWriter(const std::string& path)
    : path_((CheckReplaceableOutput(path), path)),
      partial_(path + ".partial"),
      writer_(std::make_unique<LogWriter>(partial_)) {}

ImportWriter::~ImportWriter() {
  if (!committed_) {
    writer_.reset();
    std::remove(partial_.c_str());
  }
}

void ImportWriter::WriteCalibration(int64_t utime, const CameraParams& camera, const Isometry3* T_camera_lidar,
                                    const std::string& source, const std::vector<std::pair<int, Isometry3>>& poses) {
  writer_->WriteMessage(channels::kCameraInfo, utime, CameraToMsg(camera, utime));
  if (!T_camera_lidar && poses.empty()) return;
  ground_truth_t truth{};
  truth.utime = utime;
  truth.source = source;
  ToRowMajor(T_camera_lidar ? *T_camera_lidar : Isometry3::Identity(), truth.T_camera_lidar);
  truth.camera = CameraToMsg(camera, utime);
  for (const auto& [id, pose] : poses) {
    truth.station_id.push_back(id);
    std::vector<double> m(16);
    ToRowMajor(pose, m.data());
    truth.T_world_lidar.push_back(m);
    truth.still_from_utime.push_back(0);
    truth.still_to_utime.push_back(0);
  }
  truth.num_stations = static_cast<int32_t>(truth.station_id.size());
  writer_->WriteMessage(channels::kGroundTruth, utime, truth);
}

void ImportWriter::WriteImageFile(int64_t utime, const std::vector<uint8_t>& bytes, const std::string& encoding,
                                  int width, int height) {
  image_t image{};
  image.utime = utime;
  image.frame_id = "camera";
  image.width = width;
  image.height = height;
  image.encoding = encoding;
  image.data = bytes;
  image.size = static_cast<int32_t>(bytes.size());
  writer_->WriteMessage(channels::kCameraImage, utime, image);
  ++report_.images;
}

void ImportWriter::WriteImage(int64_t utime, const cv::Mat& image) {
  writer_->WriteMessage(channels::kCameraImage, utime,
                        MatToImage(image, image.channels() == 1 ? "mono8" : "bgr8", utime));
  ++report_.images;
}

void ImportWriter::WriteScan(int64_t utime, const PointCloud& cloud) {
  writer_->WriteMessage(channels::kLidarScan, utime, CloudToMsg(cloud, utime));
  ++report_.scans;
}

void ImportWriter::WriteStation(int id, int64_t utime, const cv::Mat& image, const PointCloud& cloud,
                                const CameraParams& camera) {
  station_t station{};
  station.utime = utime;
  station.id = id;
  station.still_from_utime = utime;
  station.still_to_utime = utime;
  station.image = MatToImage(image, image.channels() == 1 ? "mono8" : "bgr8", utime);
  station.cloud = CloudToMsg(cloud, utime);
  station.camera = CameraToMsg(camera, utime);
  writer_->WriteMessage(channels::kStation, utime, station);
  ++report_.stations;
}

void ImportWriter::Commit() {
  writer_->Close();
  CheckReplaceableOutput(path_);
  fs::rename(partial_, path_);
  committed_ = true;
}

std::vector<uint8_t> ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), {});
}

std::vector<std::string> ListFiles(const std::string& dir, const std::vector<std::string>& extensions) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end())
      files.push_back(entry.path().string());
  }
  if (ec) throw std::runtime_error(dir + ": cannot list (" + ec.message() + ")");
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace fusecal
