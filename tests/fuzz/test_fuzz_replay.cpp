// Replays the fuzz corpus (tests/fuzz/corpus/<target>/: valid seeds) and every crash found so far
// (tests/fuzz/regressions/<target>/) through the entries that libFuzzer runs (fuzz_entries.hpp), in the
// ordinary build: no libFuzzer, no sanitizers; a decoder that crashes or throws anything but a
// std::exception ends this test.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"

namespace fusecal::fuzz {
namespace {

namespace fs = std::filesystem;
using Entry = int (*)(const uint8_t*, size_t);

// The same names as the fuzz_<name> executables (tests/fuzz/CMakeLists.txt).
const std::map<std::string, Entry>& Entries() {
  static const std::map<std::string, Entry> entries = {
      {"lcm_camera_info", FuzzOneLcmCameraInfo},
      {"lcm_extrinsic", FuzzOneLcmExtrinsic},
      {"lcm_ground_truth", FuzzOneLcmGroundTruth},
      {"lcm_image", FuzzOneLcmImage},
      {"lcm_motion_set", FuzzOneLcmMotionSet},
      {"lcm_motion", FuzzOneLcmMotion},
      {"lcm_point_cloud", FuzzOneLcmPointCloud},
      {"lcm_station", FuzzOneLcmStation},
      {"lcm_status", FuzzOneLcmStatus},
      {"lcm_log", FuzzOneLcmLog},
      {"ground_truth_log", FuzzOneGroundTruthLog},
#ifdef FUSECAL_WITH_DDS
      {"dds_envelope", FuzzOneDdsEnvelope},
#endif
#ifdef FUSECAL_WITH_IOX
      {"iox_chunk", FuzzOneIoxChunk},
#endif
      {"pipeline_config", FuzzOnePipelineConfig},
      {"scenario", FuzzOneScenario},
      {"result_file", FuzzOneResultFile},
      {"camera_file", FuzzOneCameraFile},
      {"kitti_calibration", FuzzOneKittiCalibration},
      {"kitti_timestamps", FuzzOneKittiTimestamps},
      {"scan_pcd", FuzzOneScanPcd},
      {"scan_ply", FuzzOneScanPly},
      {"scan_bin", FuzzOneScanBin},
      {"ply_with_pose", FuzzOnePlyWithPose},
      {"ishikawa_motions", FuzzOneIshikawaMotions},
      {"mcap", FuzzOneMcap},
      {"motion_csv", FuzzOneMotionCsv},
      {"ros_cdr", FuzzOneRosCdr},
      {"ros_livox", FuzzOneRosLivox},
      {"bus_url", FuzzOneBusUrl},
      {"channel_pattern", FuzzOneChannelPattern},
      {"extrinsic_text", FuzzOneExtrinsicText},
      {"strict_yaml", FuzzOneStrictYaml},
  };
  return entries;
}

std::vector<fs::path> FilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  return files;
}

std::set<std::string> FoldersIn(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory()) names.insert(entry.path().filename().string());
  return names;
}

std::vector<uint8_t> Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

class FuzzReplay : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, SeedsAndRegressionsDecodeWithoutCrash) {
  const Entry entry = Entries().at(GetParam());
  std::vector<fs::path> files = FilesIn(fs::path(FUZZ_CORPUS_DIR) / GetParam());
  EXPECT_FALSE(files.empty()) << "no seeds in tests/fuzz/corpus/" << GetParam();
  for (const fs::path& file : FilesIn(fs::path(FUZZ_REGRESSIONS_DIR) / GetParam())) files.push_back(file);
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    const std::vector<uint8_t> bytes = Bytes(file);
    EXPECT_EQ(entry(bytes.data(), bytes.size()), 0);
  }
}

std::vector<std::string> TargetNames() {
  std::vector<std::string> names;
  for (const auto& [name, entry] : Entries()) names.push_back(name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, ::testing::ValuesIn(TargetNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// Every folder of seeds or regressions belongs to a target (a renamed target must move its files).
TEST(FuzzCorpus, EveryFolderBelongsToATarget) {
  std::set<std::string> folders = FoldersIn(FUZZ_CORPUS_DIR);
  for (const std::string& name : FoldersIn(FUZZ_REGRESSIONS_DIR)) folders.insert(name);
  for (const std::string& name : folders) {
#ifndef FUSECAL_WITH_DDS
    if (name == "dds_envelope") continue;  // built only with Cyclone DDS
#endif
#ifndef FUSECAL_WITH_IOX
    if (name == "iox_chunk") continue;  // built only with iceoryx
#endif
    EXPECT_TRUE(Entries().count(name)) << "tests/fuzz: folder '" << name << "' is no fuzz target";
  }
}

}  // namespace
}  // namespace fusecal::fuzz
