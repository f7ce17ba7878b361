#include "runtime/io/importers/kitti.hpp"

#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "runtime/io/scan_io/scan_io.hpp"

namespace fusecal {

namespace fs = std::filesystem;

namespace {

// "KEY: v1 v2 ..." lines of a KITTI calibration file.
std::map<std::string, std::vector<double>> ReadKeyValues(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::map<std::string, std::vector<double>> values;
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::istringstream numbers(line.substr(colon + 1));
    std::vector<double> v;
    double x;
    while (numbers >> x) v.push_back(x);
    values[line.substr(0, colon)] = v;
  }
  return values;
}

const std::vector<double>& Need(const std::map<std::string, std::vector<double>>& values, const std::string& key,
                                size_t count, const std::string& path) {
  const auto it = values.find(key);
  if (it == values.end()) throw std::runtime_error(path + ": missing '" + key + "'");
  if (it->second.size() != count)
    throw std::runtime_error(path + ": '" + key + "' needs " + std::to_string(count) + " numbers, has " +
                             std::to_string(it->second.size()));
  return it->second;
}

Eigen::Matrix3d Matrix3(const std::vector<double>& v) {
  Eigen::Matrix3d M;
  for (int i = 0; i < 9; ++i) M(i / 3, i % 3) = v[i];
  return M;
}

// Frame stem -> (file, time); timestamps.txt has one line per data file, in file order.
std::map<std::string, std::pair<std::string, int64_t>> IndexSensor(const std::string& sensor_dir,
                                                                   const std::vector<std::string>& extensions) {
  const auto files = ListFiles(sensor_dir + "/data", extensions);
  const auto times = ReadKittiTimestamps(sensor_dir + "/timestamps.txt");
  if (files.size() != times.size())
    throw std::runtime_error(sensor_dir + "/timestamps.txt has " + std::to_string(times.size()) + " lines for " +
                             std::to_string(files.size()) + " data files");
  std::map<std::string, std::pair<std::string, int64_t>> index;
  for (size_t i = 0; i < files.size(); ++i) index[fs::path(files[i]).stem().string()] = {files[i], times[i]};
  return index;
}

}  // namespace

int64_t ParseKittiTimestamp(const std::string& text) {
  std::tm tm{};
  double seconds = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%d %d:%d:%lf%c", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &seconds, &extra) < 6)
    throw std::runtime_error("not a KITTI timestamp: '" + text + "'");
  // Out-of-range fields would overflow the microseconds (found by fuzzing: year 20200020).
  if (tm.tm_year < 1900 || tm.tm_year > 9999 || tm.tm_mon < 1 || tm.tm_mon > 12 || tm.tm_mday < 1 || tm.tm_mday > 31 ||
      tm.tm_hour < 0 || tm.tm_hour > 23 || tm.tm_min < 0 || tm.tm_min > 59 || !(seconds >= 0 && seconds < 61))
    throw std::runtime_error("not a KITTI timestamp: '" + text + "' (a field is out of range)");
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  tm.tm_sec = 0;
  const int64_t whole = static_cast<int64_t>(timegm(&tm));
  return whole * 1000000 + static_cast<int64_t>(std::llround(seconds * 1e6));
}

std::vector<int64_t> ReadKittiTimestamps(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<int64_t> times;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    try {
      times.push_back(ParseKittiTimestamp(line));
    } catch (const std::exception& e) {
      throw std::runtime_error(path + ": line " + std::to_string(number) + ": " + e.what());
    }
  }
  return times;
}

KittiCalibration ReadKittiCalibration(const std::string& dir) {
  const std::string velo_path = dir + "/calib_velo_to_cam.txt", cam_path = dir + "/calib_cam_to_cam.txt";
  const auto velo = ReadKeyValues(velo_path);
  const auto cam = ReadKeyValues(cam_path);
  const Isometry3 T_cam0_velo = MakeIsometry(Matrix3(Need(velo, "R", 9, velo_path)),
                                             Eigen::Map<const Eigen::Vector3d>(Need(velo, "T", 3, velo_path).data()));
  const Eigen::Matrix3d R_rect = Matrix3(Need(cam, "R_rect_00", 9, cam_path));
  const auto& P = Need(cam, "P_rect_02", 12, cam_path);
  const auto& S = Need(cam, "S_rect_02", 2, cam_path);
  KittiCalibration calib;
  calib.camera.model = "pinhole";
  calib.camera.width = static_cast<int>(std::lround(S[0]));
  calib.camera.height = static_cast<int>(std::lround(S[1]));
  calib.camera.fx = P[0];
  calib.camera.fy = P[5];
  calib.camera.cx = P[2];
  calib.camera.cy = P[6];
  // P_rect_02 = K [I | b]: the rectified camera 2 sits at -b from camera 0's rectified frame.
  const double tz = P[11];
  const Eigen::Vector3d b((P[3] - P[2] * tz) / P[0], (P[7] - P[6] * tz) / P[5], tz);
  calib.T_camera_lidar = MakeIsometry(Eigen::Matrix3d::Identity(), b) *
                         MakeIsometry(NearestRotation(R_rect), Eigen::Vector3d::Zero()) * T_cam0_velo;
  return calib;
}

ImportReport ImportKitti(const std::string& dir, const std::string& out_log, const KittiImportOptions& options,
                         const ImportProgress& progress) {
  const KittiCalibration calib = ReadKittiCalibration(dir);
  const auto images = IndexSensor(dir + "/image_02", {".png"});
  const auto scans = IndexSensor(dir + "/velodyne_points", {".bin"});
  if (images.empty() && scans.empty()) throw std::runtime_error(dir + ": no images and no scans found");

  // Events in time order: every image and scan, each at its own timestamp.
  struct Item {
    int64_t utime;
    bool is_image;
    std::string stem, path;
  };
  std::vector<Item> items;
  for (const auto& [stem, entry] : images) items.push_back({entry.second, true, stem, entry.first});
  for (const auto& [stem, entry] : scans) items.push_back({entry.second, false, stem, entry.first});
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return a.utime != b.utime ? a.utime < b.utime : a.is_image > b.is_image;
  });

  ImportWriter writer(out_log);
  writer.WriteCalibration(items.front().utime, calib.camera, &calib.T_camera_lidar,
                          "KITTI official calibration (camera 2 rectified <- velodyne)");
  // Stations: every N-th frame that has both an image and a scan; written once both are read.
  std::map<std::string, int> station_ids;
  int frame_index = 0;
  for (const auto& [stem, entry] : images) {
    if (!scans.count(stem)) continue;
    if (options.station_every > 0 && frame_index % options.station_every == 0) {
      const int id = static_cast<int>(station_ids.size());
      station_ids[stem] = id;
    }
    ++frame_index;
  }
  std::map<std::string, cv::Mat> station_images;
  std::map<std::string, PointCloud> station_clouds;
  int done = 0;
  for (const Item& item : items) {
    ++done;
    try {
      if (item.is_image) {
        const auto bytes = ReadFileBytes(item.path);
        const cv::Mat image = cv::imdecode(bytes, cv::IMREAD_COLOR);
        if (image.empty()) throw std::runtime_error(item.path + ": corrupt PNG");
        if (image.cols != calib.camera.width || image.rows != calib.camera.height)
          throw std::runtime_error(item.path + ": image is " + std::to_string(image.cols) + "x" +
                                   std::to_string(image.rows) + ", the calibration says " +
                                   std::to_string(calib.camera.width) + "x" + std::to_string(calib.camera.height));
        writer.WriteImageFile(item.utime, bytes, "png", image.cols, image.rows);
        if (station_ids.count(item.stem)) station_images[item.stem] = image;
      } else {
        const PointCloud cloud = ReadScan(item.path);
        writer.WriteScan(item.utime, cloud);
        if (station_ids.count(item.stem)) station_clouds[item.stem] = cloud;
      }
      if (station_images.count(item.stem) && station_clouds.count(item.stem)) {
        writer.WriteStation(station_ids[item.stem], item.utime, station_images[item.stem], station_clouds[item.stem],
                            calib.camera);
        station_images.erase(item.stem);
        station_clouds.erase(item.stem);
      }
    } catch (const std::exception& e) {
      writer.report().warnings.push_back(std::string(e.what()) + " (skipped)");
    }
    if (progress) progress(done, static_cast<int>(items.size()));
  }
  for (const auto& [stem, entry] : images)
    if (!scans.count(stem)) writer.report().warnings.push_back("frame " + stem + ": image without scan");
  for (const auto& [stem, entry] : scans)
    if (!images.count(stem)) writer.report().warnings.push_back("frame " + stem + ": scan without image");
  writer.Commit();
  return writer.report();
}

}  // namespace fusecal
