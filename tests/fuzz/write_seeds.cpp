// Writes the generated seeds of the fuzz corpus (tests/fuzz/corpus/<target>/) from real data: one or two
// messages of each lcmtype, small LCM logs, DDS samples of fusecal::lcm_message, ROS 2 sensor messages in
// CDR, result and camera files, scans and MCAP files as the writers produce them. The other seeds (configs,
// KITTI-format text, ascii PCD/PLY, CSV) are kept as written by hand. Usage: fuzz_write_seeds CORPUS_DIR
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/station_t.hpp"
#include "fusecal/status_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/io/scan_io/scan_io.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/camera_file.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/motion_message.hpp"
#include "stages/formats/result_file.hpp"
#include "tests/support/cdr_writer.hpp"
#include "tests/support/mcap_test_writer.hpp"
#ifdef FUSECAL_WITH_DDS
#include "dds/ddsi/ddsi_cdrstream.h"
#include "fusecal_bytes.h"
#endif

namespace fusecal {
namespace {

std::string g_corpus;

void WriteBytes(const std::string& target, const std::string& name, const std::vector<uint8_t>& bytes) {
  const std::string dir = g_corpus + "/" + target;
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/" + name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

template <typename M>
std::vector<uint8_t> Encode(const M& m) {
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

template <typename M>
void WriteMessage(const std::string& target, const std::string& name, const M& m) {
  WriteBytes(target, name, Encode(m));
}

CameraParams Pinhole() {
  CameraParams p;
  p.model = "pinhole";
  p.width = 64;
  p.height = 48;
  p.fx = p.fy = 50;
  p.cx = 32;
  p.cy = 24;
  p.dist = {-0.1, 0.01, 0, 0, 0};
  return p;
}

PointCloud SmallCloud(bool optional_fields) {
  PointCloud c;
  for (int i = 0; i < 6; ++i) {
    c.points.emplace_back(1.0f + i, 0.5f * i, -0.2f);
    if (!optional_fields) continue;
    c.intensity.push_back(0.1f * i);
    c.ring.push_back(static_cast<int16_t>(i % 2));
    c.time_offset_s.push_back(0.001f * i);
  }
  return c;
}

cv::Mat SmallImage(int type) {
  cv::Mat image(6, 8, type);
  cv::randu(image, 0, 255);
  return image;
}

motion_t Motion(int i, bool valid) {
  Isometry3 T = MakeIsometry(RotationFromRpy(0.01, 0.2, -0.1), Eigen::Vector3d(0.1, 0.02, -0.05));
  return valid ? MakeMotion(i, i + 1, "lidar", T, true, Matrix6::Identity() * 1e-4, 1000 + i)
               : MakeFailedMotion(i, i + 1, "camera", "too few matches", 1000 + i);
}

station_t Station(int id, const std::string& encoding) {
  station_t s{};
  s.utime = 5000 + id;
  s.id = id;
  s.still_from_utime = 4000;
  s.still_to_utime = 6000;
  s.image = MatToImage(SmallImage(encoding == "mono8" ? CV_8UC1 : CV_8UC3), encoding, s.utime);
  s.cloud = CloudToMsg(SmallCloud(id % 2 == 0), s.utime);
  s.camera = CameraToMsg(Pinhole(), s.utime);
  return s;
}

extrinsic_t Extrinsic() {
  extrinsic_t e{};
  e.utime = 7000;
  e.version = 2;
  ToRowMajor(MakeIsometry(RotationFromRpy(0.0, 0.1, 0.0), Eigen::Vector3d(0.1, 0.2, 0.3)), e.T_camera_lidar);
  Matrix6ToArray(Matrix6::Identity() * 1e-5, e.covariance);
  e.status = extrinsic_t::STATUS_REFINING;
  e.num_used = 2;
  e.used_station_i = {0, 1};
  e.used_station_j = {1, 2};
  e.num_rejected = 1;
  e.rejected_station_i = {2};
  e.rejected_station_j = {3};
  e.message = "refining";
  return e;
}

ground_truth_t GroundTruth() {
  ground_truth_t g{};
  g.utime = 1;
  g.source = "simulator";
  ToRowMajor(MakeIsometry(RotationFromRpy(0.0, 0.0, 0.1), Eigen::Vector3d(0.1, 0.0, -0.1)), g.T_camera_lidar);
  g.camera = CameraToMsg(Pinhole());
  g.num_stations = 2;
  g.station_id = {0, 1};
  g.T_world_lidar.assign(2, std::vector<double>(16, 0.0));
  for (auto& T : g.T_world_lidar) T[0] = T[5] = T[10] = T[15] = 1.0;
  g.still_from_utime = {10, 30};
  g.still_to_utime = {20, 40};
  return g;
}

status_t Status() {
  status_t s{};
  s.utime = 123;
  s.name = "handeye";
  s.host = "rig";
  s.pid = 42;
  s.state = "running";
  s.num_counters = 2;
  s.counter_names = {"stations", "bus_dropped"};
  s.counter_values = {4, 0};
  s.last_error = "";
  return s;
}

void WriteMessageSeeds() {
  WriteMessage("lcm_camera_info", "pinhole", CameraToMsg(Pinhole(), 10));
  CameraParams equirect;
  equirect.model = "equirectangular";
  equirect.width = 64;
  equirect.height = 32;
  WriteMessage("lcm_camera_info", "equirectangular", CameraToMsg(equirect, 10));
  WriteMessage("lcm_extrinsic", "refining", Extrinsic());
  WriteMessage("lcm_ground_truth", "two_stations", GroundTruth());
  WriteMessage("lcm_image", "mono8", MatToImage(SmallImage(CV_8UC1), "mono8", 1));
  WriteMessage("lcm_image", "rgb8", MatToImage(SmallImage(CV_8UC3), "rgb8", 1));
  WriteMessage("lcm_image", "png", MatToImage(SmallImage(CV_8UC1), "png", 1));
  WriteMessage("lcm_image", "jpeg", MatToImage(SmallImage(CV_8UC3), "jpeg", 1));
  motion_set_t set{};
  set.utime = 9;
  set.extrinsic_version = 2;
  set.motions = {Motion(0, true), Motion(1, false)};
  set.num_motions = 2;
  WriteMessage("lcm_motion_set", "two_motions", set);
  WriteMessage("lcm_motion", "valid", Motion(0, true));
  WriteMessage("lcm_motion", "failed", Motion(1, false));
  WriteMessage("lcm_point_cloud", "xyz", CloudToMsg(SmallCloud(false), 1));
  WriteMessage("lcm_point_cloud", "all_fields", CloudToMsg(SmallCloud(true), 1));
  WriteMessage("lcm_station", "mono8", Station(0, "mono8"));
  WriteMessage("lcm_station", "jpeg", Station(1, "jpeg"));
  WriteMessage("lcm_status", "running", Status());
}

std::vector<uint8_t> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// A log written by LogWriter, as bytes.
template <typename Fill>
std::vector<uint8_t> Log(Fill fill) {
  const std::string path = std::filesystem::temp_directory_path() / "fusecal-seed.log";
  {
    LogWriter writer(path);
    fill(writer);
    writer.Close();
  }
  std::vector<uint8_t> bytes = ReadFile(path);
  std::filesystem::remove(path);
  return bytes;
}

void WriteLogSeeds() {
  WriteBytes("lcm_log", "mixed", Log([](LogWriter& w) {
               w.WriteMessage(channels::kStatus, 1, Status());
               w.WriteMessage(channels::kLidarMotion, 2, Motion(0, true));
               w.WriteMessage(channels::kExtrinsic, 3, Extrinsic());
               w.Write("EMPTY", 4, "", 0);
             }));
  WriteBytes("lcm_log", "station",
             Log([](LogWriter& w) { w.WriteMessage(channels::kStation, 5, Station(0, "mono8")); }));
  WriteBytes("lcm_log", "empty", {});
  WriteBytes("ground_truth_log", "truth", Log([](LogWriter& w) {
               w.WriteMessage(channels::kStatus, 1, Status());
               w.WriteMessage(channels::kGroundTruth, 2, GroundTruth());
             }));
  WriteBytes("ground_truth_log", "moved", Log([](LogWriter& w) {  // the camera moved on its mount at 25
               w.WriteMessage(channels::kGroundTruth, 1, GroundTruth());
               ground_truth_t moved = GroundTruth();
               moved.utime = 25;
               ToRowMajor(FromRowMajor(moved.T_camera_lidar) *
                              MakeIsometry(RotationFromRpy(0.02, 0.0, 0.0), Eigen::Vector3d(0.02, 0.0, 0.0)),
                          moved.T_camera_lidar);
               w.WriteMessage(channels::kGroundTruth, 25, moved);
             }));
}

void WriteText(const std::string& target, const std::string& name, const std::string& text) {
  WriteBytes(target, name, std::vector<uint8_t>(text.begin(), text.end()));
}

// A scan file as WriteScan writes it.
void WriteScanSeed(const std::string& target, const std::string& name, const PointCloud& cloud) {
  const std::string path = std::filesystem::temp_directory_path() / name;
  WriteScan(path, cloud);
  WriteBytes(target, name, ReadFile(path));
  std::filesystem::remove(path);
}

void WriteFileSeeds() {
  CalibrationResult result, initial;
  result.T_camera_lidar = MakeIsometry(RotationFromRpy(0.0, 0.1, 0.0), Eigen::Vector3d(0.1, 0.2, 0.3));
  result.covariance = Matrix6::Identity() * 1e-6;
  result.status = "converged";
  result.observability = "ok";
  result.motions_used = {"0-1", "1-2"};
  result.motions_rejected = {"2-3: rotation angles differ by 3.1 deg"};
  result.residual_rms = 0.002;
  result.extra["iterations"] = "3";
  initial.T_camera_lidar = result.T_camera_lidar;
  WriteText("result_file", "with_initial.yaml", ResultToYaml(result, &initial));
  WriteText("camera_file", "pinhole.yaml", CameraToYaml(Pinhole()));
  WriteScanSeed("scan_pcd", "binary.pcd", SmallCloud(true));
  WriteScanSeed("scan_ply", "binary.ply", SmallCloud(true));
  WriteScanSeed("scan_bin", "six_points.bin", SmallCloud(false));
  WriteScanSeed("ply_with_pose", "binary.ply", SmallCloud(false));
}

// ROS 2 sensor messages in CDR behind the byte that chooses their type (entries_ros_cdr.cpp).
template <typename M>
void WriteRosCdrSeed(uint8_t selector, const std::string& name, const M& msg, testing::CdrByteOrder order) {
  std::vector<uint8_t> bytes = {selector};
  const std::vector<uint8_t> cdr = testing::EncodeCdr(msg, order);
  bytes.insert(bytes.end(), cdr.begin(), cdr.end());
  WriteBytes("ros_cdr", name, bytes);
}

RosPointCloud2 RosCloud() {
  RosPointCloud2 msg;
  msg.header = RosHeader{RosTime{1700000000, 5000}, "velodyne"};
  msg.height = 1;
  msg.width = 3;
  msg.fields = {{"x", 0, RosPointField::FLOAT32, 1},
                {"y", 4, RosPointField::FLOAT32, 1},
                {"z", 8, RosPointField::FLOAT32, 1},
                {"intensity", 12, RosPointField::FLOAT32, 1},
                {"ring", 16, RosPointField::UINT16, 1}};
  msg.point_step = 18;
  msg.row_step = 54;
  const PointCloud cloud = SmallCloud(true);
  msg.data.assign(54, 0);
  for (int i = 0; i < 3; ++i) {
    std::memcpy(&msg.data[18 * i], cloud.points[i].data(), 12);
    std::memcpy(&msg.data[18 * i + 12], &cloud.intensity[i], 4);
  }
  return msg;
}

// Livox's PointCloud2 layout (x, y, z, intensity float32, tag, line uint8, timestamp float64, packed).
RosPointCloud2 RosLivoxCloud() {
  RosPointCloud2 msg;
  msg.header = RosHeader{RosTime{1700000000, 5000}, "livox_frame"};
  msg.height = 1;
  msg.width = 3;
  msg.fields = {{"x", 0, RosPointField::FLOAT32, 1},         {"y", 4, RosPointField::FLOAT32, 1},
                {"z", 8, RosPointField::FLOAT32, 1},         {"intensity", 12, RosPointField::FLOAT32, 1},
                {"tag", 16, RosPointField::UINT8, 1},        {"line", 17, RosPointField::UINT8, 1},
                {"timestamp", 18, RosPointField::FLOAT64, 1}};
  msg.point_step = 26;
  msg.row_step = 78;
  const PointCloud cloud = SmallCloud(true);
  msg.data.assign(78, 0);
  for (int i = 0; i < 3; ++i) {
    std::memcpy(&msg.data[26 * i], cloud.points[i].data(), 12);
    std::memcpy(&msg.data[26 * i + 12], &cloud.intensity[i], 4);
    msg.data[26 * i + 17] = static_cast<uint8_t>(i);
    const double t = 1700000000000005000.0 + 5000.0 * i;
    std::memcpy(&msg.data[26 * i + 18], &t, 8);
  }
  return msg;
}

// Livox's CustomMsg behind the byte that chooses CDR (0) or ROS 1 (1) (entries_ros_cdr.cpp).
void WriteRosLivoxSeeds() {
  RosLivoxCustomMsg msg;
  msg.header = RosHeader{RosTime{1700000000, 5000}, "livox_frame"};
  msg.timebase = 1700000000000005000ull;
  msg.points = {{0, 1.5f, -2.f, 0.25f, 10, 0x10, 0}, {5000, 3.f, 4.f, -5.f, 200, 0, 3}};
  msg.point_num = 2;
  for (const auto order : {testing::CdrByteOrder::kLittle, testing::CdrByteOrder::kBig}) {
    std::vector<uint8_t> bytes = {0};
    const std::vector<uint8_t> cdr = testing::EncodeCdr(msg, order);
    bytes.insert(bytes.end(), cdr.begin(), cdr.end());
    WriteBytes("ros_livox", order == testing::CdrByteOrder::kLittle ? "cdr_le" : "cdr_be", bytes);
  }
  // ROS 1: seq, stamp, frame_id without NUL; timebase, point_num, lidar_id, rsvd; points packed (19 bytes).
  std::vector<uint8_t> ros1 = {1};
  const auto put = [&ros1](const void* p, size_t n) {
    ros1.insert(ros1.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
  };
  const uint32_t header[4] = {7, 1700000000, 5000, static_cast<uint32_t>(msg.header.frame_id.size())};
  put(header, sizeof(header));
  put(msg.header.frame_id.data(), msg.header.frame_id.size());
  put(&msg.timebase, 8);
  put(&msg.point_num, 4);
  ros1.insert(ros1.end(), {msg.lidar_id, 0, 0, 0});
  const uint32_t count = 2;
  put(&count, 4);
  for (const RosLivoxPoint& p : msg.points) {
    put(&p.offset_time, 4);
    put(&p.x, 4);
    put(&p.y, 4);
    put(&p.z, 4);
    ros1.insert(ros1.end(), {p.reflectivity, p.tag, p.line});
  }
  WriteBytes("ros_livox", "ros1", ros1);
}

void WriteRosCdrSeeds() {
  using testing::CdrByteOrder;
  WriteRosCdrSeed(0, "cloud_le", RosCloud(), CdrByteOrder::kLittle);
  WriteRosCdrSeed(0, "cloud_be", RosCloud(), CdrByteOrder::kBig);
  WriteRosCdrSeed(0, "cloud_livox_le", RosLivoxCloud(), CdrByteOrder::kLittle);
  const cv::Mat grey = SmallImage(CV_8UC1);
  RosImage image;
  image.header = RosHeader{RosTime{1700000000, 0}, "camera"};
  image.height = static_cast<uint32_t>(grey.rows);
  image.width = static_cast<uint32_t>(grey.cols);
  image.encoding = "mono8";
  image.step = image.width;
  image.data.assign(grey.data, grey.data + grey.total());
  WriteRosCdrSeed(1, "image_mono8_le", image, CdrByteOrder::kLittle);
  image.encoding = "mono16";
  image.width /= 2;
  image.is_bigendian = 1;
  WriteRosCdrSeed(1, "image_mono16_be", image, CdrByteOrder::kBig);
  RosCompressedImage compressed;
  compressed.header = image.header;
  compressed.format = "mono8; png compressed";
  cv::imencode(".png", grey, compressed.data);
  WriteRosCdrSeed(2, "compressed_png", compressed, CdrByteOrder::kLittle);
  RosCameraInfo info;
  info.header = image.header;
  info.height = 48;
  info.width = 64;
  info.distortion_model = "plumb_bob";
  info.D = {-0.1, 0.01, 0, 0, 0};
  info.K = {50, 0, 32, 0, 50, 24, 0, 0, 1};
  WriteRosCdrSeed(3, "camera_info_le", info, CdrByteOrder::kLittle);
  info.distortion_model = "equidistant";
  info.D = {0.02, -0.006, 0.0009, -0.0002};
  WriteRosCdrSeed(3, "camera_info_equidistant_be", info, CdrByteOrder::kBig);
}

// MCAP files as the tests' writer makes them (entries_rosbag2.cpp): each compression, chunked or not, with
// and without summary, and one cut short in a chunk. Small messages keep each under 16 kB.
void WriteMcapSeeds() {
  const std::vector<testing::BagTopic> topics = {{"/camera/image_raw", "sensor_msgs/msg/Image"},
                                                 {"/lidar/points", "sensor_msgs/msg/PointCloud2"}};
  std::vector<testing::BagMessage> messages;
  for (int i = 0; i < 9; ++i) {
    testing::BagMessage m;
    m.topic = i % 2;
    m.log_time_ns = 1'700'000'000'000'000'000 + (i == 4 ? 2 : i) * 10'000'000;  // one written late
    m.data.assign(40 + 13 * i, static_cast<uint8_t>(i));
    messages.push_back(m);
  }
  WriteBytes("mcap", "zstd_summary.mcap", testing::WriteMcap(topics, messages, {"zstd", true, 3, true}).bytes);
  WriteBytes("mcap", "lz4_no_summary.mcap", testing::WriteMcap(topics, messages, {"lz4", true, 4, false}).bytes);
  WriteBytes("mcap", "uncompressed_chunks.mcap", testing::WriteMcap(topics, messages, {"", true, 2, true}).bytes);
  WriteBytes("mcap", "unchunked.mcap", testing::WriteMcap(topics, messages, {"", false, 0, true}).bytes);
  testing::McapTestFile cut = testing::WriteMcap(topics, messages, {"zstd", true, 3, false});
  cut.bytes.resize(cut.chunk_offsets.back() + 40);
  WriteBytes("mcap", "cut_short.mcap", cut.bytes);
}

#ifdef FUSECAL_WITH_DDS
// A fusecal::lcm_message sample as DdsBus writes it, serialized with its encapsulation header.
std::vector<uint8_t> DdsSample(const std::vector<uint8_t>& lcm, uint32_t xcdr_version, bool big_endian) {
  fusecal_lcm_message m{};
  std::string channel = channels::kStatus.name;
  m.channel = channel.data();
  m.utime = 1700000000000000;
  m.seq_number = 7;
  m.data._length = m.data._maximum = static_cast<uint32_t>(lcm.size());
  m.data._buffer = const_cast<uint8_t*>(lcm.data());
  dds_ostream_t os;
  dds_ostream_init(&os, 0, xcdr_version);
  const char* sample = reinterpret_cast<const char*>(&m);
  if (big_endian)
    dds_stream_writeBE(reinterpret_cast<dds_ostreamBE_t*>(&os), sample, fusecal_lcm_message_desc.m_ops);
  else
    dds_stream_writeLE(reinterpret_cast<dds_ostreamLE_t*>(&os), sample, fusecal_lcm_message_desc.m_ops);
  const uint8_t id = static_cast<uint8_t>((xcdr_version == 2 ? 0x06 : 0x00) | (big_endian ? 0 : 1));
  // Sized at once: gcc 12 takes an insert after the 4-byte header for a write past it (-Warray-bounds).
  std::vector<uint8_t> bytes(4 + os.m_index, 0);
  bytes[1] = id;
  if (os.m_index > 0) std::memcpy(bytes.data() + 4, os.m_buffer, os.m_index);
  dds_ostream_fini(&os);
  return bytes;
}

void WriteDdsSeeds() {
  const std::vector<uint8_t> status = Encode(Status());
  WriteBytes("dds_envelope", "status_cdr_le", DdsSample(status, 1, false));
  WriteBytes("dds_envelope", "status_cdr2_be", DdsSample(status, 2, true));
  WriteBytes("dds_envelope", "motion_cdr_le", DdsSample(Encode(Motion(0, true)), 1, false));
}
#else
void WriteDdsSeeds() { std::cerr << "fuzz_write_seeds: built without DDS, no dds_envelope seeds\n"; }
#endif

}  // namespace
}  // namespace fusecal

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_write_seeds CORPUS_DIR (tests/fuzz/corpus)\n";
    return 2;
  }
  fusecal::g_corpus = argv[1];
  fusecal::WriteMessageSeeds();
  fusecal::WriteLogSeeds();
  fusecal::WriteFileSeeds();
  fusecal::WriteDdsSeeds();
  fusecal::WriteRosCdrSeeds();
  fusecal::WriteRosLivoxSeeds();
  fusecal::WriteMcapSeeds();
  return 0;
}
