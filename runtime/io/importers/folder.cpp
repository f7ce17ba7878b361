#include "runtime/io/importers/folder.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "runtime/io/scan_io/scan_io.hpp"

namespace fusecal {

namespace fs = std::filesystem;

namespace {

std::map<std::string, int64_t> ReadTimes(const std::string& path) {
  std::map<std::string, int64_t> times;
  std::ifstream in(path);
  if (!in) return times;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto comma = line.find(',');
    if (line.empty() || comma == std::string::npos) continue;
    try {
      times[line.substr(0, comma)] = static_cast<int64_t>(std::llround(std::stod(line.substr(comma + 1)) * 1e6));
    } catch (const std::exception&) {
      if (number > 1) throw std::runtime_error(path + ": line " + std::to_string(number) + " has no time in seconds");
    }
  }
  return times;
}

}  // namespace

ImportReport ImportFolder(const std::string& dir, const CameraParams& camera, const std::string& out_log,
                          const ImportProgress& progress) {
  const auto image_files = ListFiles(dir, {".png", ".jpg", ".jpeg"});
  const auto scan_files = ListFiles(dir, {".pcd", ".ply", ".bin"});
  std::map<std::string, std::string> images, scans;
  for (const auto& f : image_files) images[fs::path(f).stem().string()] = f;
  for (const auto& f : scan_files) scans[fs::path(f).stem().string()] = f;
  const auto times = ReadTimes(dir + "/times.csv");

  ImportWriter writer(out_log);
  std::vector<std::string> stems;
  for (const auto& [stem, path] : images) {
    if (scans.count(stem))
      stems.push_back(stem);
    else
      writer.report().warnings.push_back(path + ": image without a scan of the same name (skipped)");
  }
  for (const auto& [stem, path] : scans)
    if (!images.count(stem)) writer.report().warnings.push_back(path + ": scan without an image (skipped)");
  if (stems.empty()) throw std::runtime_error(dir + ": no image and scan share a file name");

  writer.WriteCalibration(0, camera, nullptr, "");
  int id = 0, done = 0;
  for (const auto& stem : stems) {
    const int64_t utime = times.count(stem) ? times.at(stem) : int64_t(id + 1) * 1000000;
    try {
      const auto bytes = ReadFileBytes(images[stem]);
      const cv::Mat image = cv::imdecode(bytes, cv::IMREAD_COLOR);
      if (image.empty()) throw std::runtime_error(images[stem] + ": corrupt or unreadable image");
      if (image.cols != camera.width || image.rows != camera.height)
        throw std::runtime_error(images[stem] + ": image is " + std::to_string(image.cols) + "x" +
                                 std::to_string(image.rows) + ", the camera file says " + std::to_string(camera.width) +
                                 "x" + std::to_string(camera.height));
      const PointCloud cloud = ReadScan(scans[stem]);
      writer.WriteImageFile(
          utime, bytes,
          images[stem].size() > 4 && images[stem].substr(images[stem].size() - 4) == ".png" ? "png" : "jpeg",
          image.cols, image.rows);
      writer.WriteScan(utime, cloud);
      writer.WriteStation(id++, utime, image, cloud, camera);
    } catch (const std::exception& e) {
      writer.report().warnings.push_back(std::string(e.what()) + " (skipped)");
    }
    if (progress) progress(++done, static_cast<int>(stems.size()));
  }
  writer.Commit();
  return writer.report();
}

}  // namespace fusecal
