// Fuzz entries of the importers' parsers and the scan files (fuzz_entries.hpp): the bytes are a whole
// file (for the KITTI calibration, two files).
#include <string>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/io/importers/ishikawa.hpp"
#include "runtime/io/importers/kitti.hpp"
#include "runtime/io/scan_io/scan_io.hpp"

namespace fusecal::fuzz {

namespace {

int FuzzOneScan(const uint8_t* data, size_t size, const std::string& name) {
  const std::string path = WriteScratchFile(name, data, size);
  IgnoringRejection([&] { ReadScan(path); });
  return 0;
}

}  // namespace

// calib_velo_to_cam.txt, a line "----", calib_cam_to_cam.txt (without the line: the second file is empty).
int FuzzOneKittiCalibration(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n----\n";
  const size_t split = text.find(separator);
  const std::string velo = text.substr(0, split);
  const std::string cam = split == std::string::npos ? "" : text.substr(split + separator.size());
  WriteScratchFile("calib_velo_to_cam.txt", reinterpret_cast<const uint8_t*>(velo.data()), velo.size());
  WriteScratchFile("calib_cam_to_cam.txt", reinterpret_cast<const uint8_t*>(cam.data()), cam.size());
  IgnoringRejection([&] { ReadKittiCalibration(ScratchFolder()); });
  return 0;
}

int FuzzOneKittiTimestamps(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("timestamps.txt", data, size);
  IgnoringRejection([&] { ReadKittiTimestamps(path); });
  return 0;
}

int FuzzOneScanPcd(const uint8_t* data, size_t size) { return FuzzOneScan(data, size, "scan.pcd"); }
int FuzzOneScanPly(const uint8_t* data, size_t size) { return FuzzOneScan(data, size, "scan.ply"); }
int FuzzOneScanBin(const uint8_t* data, size_t size) { return FuzzOneScan(data, size, "scan.bin"); }

int FuzzOnePlyWithPose(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("position1.ply", data, size);
  IgnoringRejection([&] { ReadPlyWithPose(path); });
  return 0;
}

int FuzzOneIshikawaMotions(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("motion.txt", data, size);
  IgnoringRejection([&] { ReadMotionPairs(path); });
  return 0;
}

}  // namespace fusecal::fuzz
