#include "runtime/io/importers/ishikawa.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <regex>

namespace fusecal {

namespace fs = std::filesystem;

Eigen::Matrix3d RotationTheirsFromFusecal() {
  Eigen::Matrix3d R_fusecal_theirs;
  R_fusecal_theirs << 0, -1, 0,  // x = -y_t
      0, 0, -1,                  // y = -z_t
      1, 0, 0;                   // z =  x_t
  return R_fusecal_theirs.transpose();
}

std::vector<std::pair<int, int>> ReadMotionPairs(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<std::pair<int, int>> pairs;
  std::string line;
  int number = 0;
  const std::regex pair_pattern(R"(\s*(\d+)\s*-\s*(\d+)\s*)");
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    std::smatch m;
    if (!std::regex_match(line, m, pair_pattern) || std::stoi(m[1]) < 1 || std::stoi(m[2]) < 1)
      throw std::runtime_error(path + ": line " + std::to_string(number) + " is not 'a-b' with 1-based numbers: '" +
                               line + "'");
    pairs.emplace_back(std::stoi(m[1]) - 1, std::stoi(m[2]) - 1);
  }
  return pairs;
}

ImportReport ImportIshikawa(const std::string& dir, const std::string& out_log, const ImportProgress& progress) {
  const std::regex name_pattern(R"(position(\d+))");
  std::map<int, std::string> scans, images;
  for (const auto& f : ListFiles(dir, {".ply", ".jpg", ".jpeg", ".png"})) {
    std::smatch m;
    const std::string stem = fs::path(f).stem().string();
    if (!std::regex_match(stem, m, name_pattern)) continue;
    const int number = std::stoi(m[1]);
    (fs::path(f).extension() == ".ply" ? scans : images)[number] = f;
  }
  if (scans.empty()) throw std::runtime_error(dir + ": no position<N>.ply scans");
  const std::string motion_path = dir + "/motion.txt";
  const auto motions = fs::exists(motion_path) ? ReadMotionPairs(motion_path) : std::vector<std::pair<int, int>>{};

  ImportWriter writer(out_log);
  struct Station {
    int id;
    cv::Mat image;
    std::vector<uint8_t> bytes;
    PosedScan scan;
  };
  std::vector<Station> stations;
  int done = 0;
  for (const auto& [number, scan_path] : scans) {
    if (progress) progress(++done, static_cast<int>(scans.size()));
    if (!images.count(number)) {
      writer.report().warnings.push_back(scan_path + ": no position" + std::to_string(number) + ".jpg (skipped)");
      continue;
    }
    try {
      Station s;
      s.id = number - 1;  // station ids are 0-based; motion.txt numbers are 1-based
      s.bytes = ReadFileBytes(images[number]);
      s.image = cv::imdecode(s.bytes, cv::IMREAD_COLOR);
      if (s.image.empty()) throw std::runtime_error(images[number] + ": corrupt or unreadable image");
      if (s.image.cols != 2 * s.image.rows)
        throw std::runtime_error(images[number] + ": a panorama must be twice as wide as high");
      s.scan = ReadPlyWithPose(scan_path);
      stations.push_back(std::move(s));
    } catch (const std::exception& e) {
      writer.report().warnings.push_back(std::string(e.what()) + " (skipped)");
    }
  }
  if (stations.empty()) throw std::runtime_error(dir + ": no usable station");
  for (const auto& [a, b] : motions) {
    const auto has = [&](int id) {
      for (const auto& s : stations)
        if (s.id == id) return true;
      return false;
    };
    if (!has(a) || !has(b))
      writer.report().warnings.push_back("motion.txt: pair " + std::to_string(a + 1) + "-" + std::to_string(b + 1) +
                                         " names a station that was not imported");
  }

  CameraParams camera;
  camera.model = "equirectangular";
  camera.width = stations.front().image.cols;
  camera.height = stations.front().image.rows;
  std::vector<std::pair<int, Isometry3>> poses;
  for (const auto& s : stations) {
    if (!s.scan.pose) continue;
    Isometry3 pose;
    pose.matrix() = *s.scan.pose;
    poses.emplace_back(s.id, pose);
  }
  writer.WriteCalibration(1000000, camera, nullptr, "ishikawa dataset: station poses from the PLY headers", poses);
  for (const auto& s : stations) {
    const int64_t utime = int64_t(s.id + 1) * 1000000 + 1;
    if (s.image.cols != camera.width) {
      writer.report().warnings.push_back("station " + std::to_string(s.id + 1) + ": panorama size differs (skipped)");
      continue;
    }
    writer.WriteImageFile(utime, s.bytes, "jpeg", s.image.cols, s.image.rows);
    writer.WriteScan(utime, s.scan.cloud);
    writer.WriteStation(s.id, utime, s.image, s.scan.cloud, camera);
  }
  writer.Commit();
  return writer.report();
}

}  // namespace fusecal
