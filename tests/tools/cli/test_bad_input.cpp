// The bad-input suite: every command given inputs that are wrong in one way (empty, truncated,
// bit-flipped, of another kind, degenerate) must end with a clear error naming the input, an exit code
// between 1 and 125 (not a crash: a signal shows as 128+N through the shell, a hang as timeout's 124),
// and never report "converged". The inputs are written by the test itself.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/lcm_log.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::ReadAll;
using testing::RunCommand;
using testing::StartInBackground;

const std::string kFusecal = FUSECAL_BIN;
const std::string kScenarios = SCENARIO_DIR;
const std::string kConfig = PIPELINE_CONFIG;

std::string Dir() {
  static const std::string dir = [] {
    const std::string d = ::testing::TempDir() + "fusecal_bad_" + std::to_string(getpid());
    RunCommand("mkdir -p " + d);
    return d;
  }();
  return dir;
}
std::string In(const std::string& name) { return Dir() + "/" + name; }

void WriteAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// A small valid log with stations, made once (the tiny scenario, stations only).
const std::string& GoodLog() {
  static const std::string log = [] {
    const std::string path = In("good.lcmlog");
    RunCommand(kFusecal + " simulate --scenario " + kScenarios + "/tiny-equirect.yaml --stations-only --out " + path +
               " 2>&1");
    return path;
  }();
  return log;
}

void WriteBin(const std::string& path, const std::vector<float>& xyzi) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(xyzi.data()), static_cast<std::streamsize>(xyzi.size() * sizeof(float)));
}

// A room: walls of a 10 m x 6 m box, floor, ceiling and a pillar (no symmetry, every direction
// constrained), as a KITTI .bin holds it (x, y, z, intensity).
std::vector<float> BoxCloud() {
  std::vector<float> v;
  auto add = [&](float x, float y, float z) { v.insert(v.end(), {x, y, z, 0.5f}); };
  for (int a = 0; a <= 50; ++a)
    for (int b = 0; b <= 20; ++b) {
      const float s = a / 50.0f, h = -1.5f + 3.5f * b / 20.0f;
      add(5, -3 + 6 * s, h), add(-5, -3 + 6 * s, h), add(-5 + 10 * s, 3, h), add(-5 + 10 * s, -3, h);
      add(-5 + 10 * s, -3 + 6 * b / 20.0f, -1.5f), add(-5 + 10 * s, -3 + 6 * b / 20.0f, 2.0f);
      add(2.0f + 0.3f * std::cos(6.28f * s), 1.0f + 0.3f * std::sin(6.28f * s), h);
    }
  return v;
}

void WriteCamera(const std::string& path, const std::string& text) { WriteAll(path, text); }
const char* kPanoramaCamera = "model: equirectangular\nwidth: 256\nheight: 128\n";

std::string CsvHeader() { return "a_qw,a_qx,a_qy,a_qz,a_tx,a_ty,a_tz,b_qw,b_qx,b_qy,b_qz,b_tx,b_ty,b_tz\n"; }

// Rotations about the z axis only (A = B: X = identity), which leave part of X undetermined.
std::string OneAxisCsv(int rows) {
  std::string csv = CsvHeader();
  for (int k = 1; k <= rows; ++k) {
    const double half = 0.5 * (10.0 + 7.0 * k) * M_PI / 180.0;
    const std::string q = std::to_string(std::cos(half)) + ",0,0," + std::to_string(std::sin(half));
    const std::string t = std::to_string(0.1 * k) + "," + std::to_string(0.05 * k) + ",0";
    csv += q + "," + t + "," + q + "," + t + "\n";
  }
  return csv;
}

// A config: the pipeline's own with one line appended under `section` (or at the top level).
std::string ConfigWith(const std::string& name, const std::string& section, const std::string& line) {
  std::string text = ReadAll(kConfig);
  if (section.empty()) {
    text += line + "\n";
  } else {
    const size_t at = text.find("\n" + section + ":");
    const size_t eol = text.find('\n', at + 1);
    std::string head = text.substr(at + 1, eol - at - 1);
    if (head.find("{}") != std::string::npos) text.replace(at + 1, eol - at - 1, section + ":");
    const size_t insert = text.find('\n', at + 1);
    text.insert(insert + 1, "  " + line + "\n");
  }
  const std::string path = In(name);
  WriteAll(path, text);
  return path;
}

// A copy of the good log with one extra STATION event whose bytes are `payload`.
std::string LogWithStationBytes(const std::string& name, const std::vector<uint8_t>& payload) {
  const std::string path = In(name);
  WriteAll(path, ReadAll(GoodLog()));
  {
    LogReader reader(GoodLog());
    LogWriter writer(path);
    int64_t last = 0;
    while (auto e = reader.Next()) {
      writer.Write(e->channel, e->utime, e->data.data(), e->data.size());
      last = e->utime;
    }
    writer.Write("STATION", last + 1000, payload.data(), payload.size());
  }
  return path;
}

struct BadCase {
  std::string name;
  std::function<void()> make;  // writes the inputs
  std::string command;         // after `fusecal `
  std::string names;           // the output must contain this (the input, or what is wrong with it)
  // false: a bad message inside a log that the pipeline rejects (logged) and goes on without; the
  // answer from the rest may well be "converged".
  bool fails = true;
};
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

std::vector<BadCase> Cases() {
  const std::string log = In("bad.lcmlog"), scan = In("bad.bin"), good_scan = In("box.bin");
  const std::string image = In("bad.png"), good_image = In("good.png"), camera = In("camera.yaml");
  const std::string csv = In("bad.csv"), result = In("out.yaml");
  auto good_inputs = [=] {
    WriteBin(good_scan, BoxCloud());
    cv::Mat textured(128, 256, CV_8UC1);
    cv::randu(textured, 0, 255);
    cv::imwrite(good_image, textured);
    WriteCamera(camera, kPanoramaCamera);
  };
  auto calibrate = [](const std::string& l) { return "calibrate --log " + l + " --out " + In("cal-out"); };
  std::vector<BadCase> c;
  // --- logs ---
  c.push_back({"EmptyLog", [=] { WriteAll(log, ""); }, calibrate(log), "bad.lcmlog"});
  c.push_back({"EmptyLogInfo", [=] { WriteAll(log, ""); }, "log info " + log, "bad.lcmlog: no events"});
  c.push_back({"TruncatedLog",
               [=] {
                 const std::string b = ReadAll(GoodLog());
                 WriteAll(log, b.substr(0, b.size() / 2));
               },
               calibrate(log), "truncated"});
  c.push_back({"TruncatedLogDump",
               [=] {
                 const std::string b = ReadAll(GoodLog());
                 WriteAll(log, b.substr(0, 100));
               },
               "log dump " + log, "truncated"});
  c.push_back({"BitFlippedLog",
               [=] {
                 std::string b = ReadAll(GoodLog());
                 for (size_t k = 20; k < b.size(); k += 997) b[k] = static_cast<char>(b[k] ^ 0x5a);
                 WriteAll(log, b);
               },
               calibrate(log), "bad.lcmlog"});
  c.push_back({"PngAsLog",
               [=] {
                 good_inputs();
                 WriteAll(log, ReadAll(good_image));
               },
               calibrate(log), "bad.lcmlog"});
  c.push_back({"MissingLog", [] {}, calibrate(In("absent.lcmlog")), "absent.lcmlog"});
  c.push_back({"StationOfAnotherType",
               [=] {
                 camera_info_t info{};
                 info.model = "pinhole";
                 std::vector<uint8_t> bytes(info.getEncodedSize());
                 info.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
                 LogWithStationBytes("wrong-type.lcmlog", bytes);
               },
               calibrate(In("wrong-type.lcmlog")),
               "stage error (continuing): cannot decode a station_t on channel STATION", false});
  c.push_back({"StationCutShort",
               [=] {
                 LogReader reader(GoodLog());
                 std::vector<uint8_t> station;
                 while (auto e = reader.Next())
                   if (e->channel == "STATION") {
                     station = e->data;
                     break;
                   }
                 station.resize(station.size() / 3);
                 LogWithStationBytes("short-station.lcmlog", station);
               },
               calibrate(In("short-station.lcmlog")),
               "stage error (continuing): cannot decode a station_t on channel STATION", false});
  // --- scans ---
  c.push_back({"EmptyScan",
               [=] {
                 good_inputs();
                 WriteAll(scan, "");
               },
               "register " + scan + " " + good_scan, "bad.bin -> " + good_scan + ": scan i has 0 valid points of 0"});
  c.push_back({"AllNanScan",
               [=] {
                 good_inputs();
                 WriteBin(scan, std::vector<float>(4000, NAN));
               },
               "register " + good_scan + " " + scan, "scan j has 0 valid points of 1000"});
  c.push_back({"OnePointScan",
               [=] {
                 good_inputs();
                 WriteBin(scan, {1, 2, 3, 0});
               },
               "register " + good_scan + " " + scan, "reason"});
  c.push_back({"ScanOfOddSize",
               [=] {
                 good_inputs();
                 WriteAll(scan, std::string(4 * 4 * 10 + 6, '\1'));
               },
               "register " + scan + " " + good_scan, "bad.bin"});
  c.push_back({"TextAsPcd",
               [=] {
                 good_inputs();
                 WriteAll(In("bad.pcd"), "this is not a point cloud\n");
               },
               "register " + In("bad.pcd") + " " + good_scan, "bad.pcd"});
  c.push_back({"ScanOfUnknownKind",
               [=] {
                 good_inputs();
                 WriteAll(In("bad.xyz"), "1 2 3\n");
               },
               "register " + In("bad.xyz") + " " + good_scan, "unsupported extension"});
  // --- images ---
  c.push_back({"EmptyImageFile",
               [=] {
                 good_inputs();
                 WriteAll(image, "");
               },
               "camera-motion " + image + " " + good_image + " --camera " + camera, "bad.png"});
  c.push_back({"OnePixelImage",
               [=] {
                 good_inputs();
                 cv::imwrite(image, cv::Mat(1, 1, CV_8UC1, cv::Scalar(9)));
               },
               "camera-motion " + image + " " + good_image + " --camera " + camera, "1x1"});
  c.push_back({"BlackImages",
               [=] {
                 good_inputs();
                 cv::imwrite(image, cv::Mat(128, 256, CV_8UC1, cv::Scalar(0)));
               },
               "camera-motion " + image + " " + image + " --camera " + camera, "reason"});
  c.push_back({"ImageOfAnotherSize",
               [=] {
                 good_inputs();
                 cv::imwrite(image, cv::Mat(100, 300, CV_8UC1, cv::Scalar(50)));
               },
               "camera-motion " + good_image + " " + image + " --camera " + camera, "300x100"});
  c.push_back({"CameraOfUnknownModel",
               [=] {
                 good_inputs();
                 WriteCamera(In("bad-camera.yaml"), "model: fisheye\nwidth: 256\nheight: 128\n");
               },
               "camera-motion " + good_image + " " + good_image + " --camera " + In("bad-camera.yaml"), "model"});
  c.push_back({"CameraWithNegativeFocalLength",
               [=] {
                 good_inputs();
                 WriteCamera(In("bad-camera.yaml"),
                             "model: pinhole\nwidth: 256\nheight: 128\nfx: -100\nfy: 100\ncx: 128\ncy: 64\n");
               },
               "camera-motion " + good_image + " " + good_image + " --camera " + In("bad-camera.yaml"), "fx"});
  // --- motions ---
  c.push_back({"MotionsWithNan", [=] { WriteAll(csv, CsvHeader() + "nan,0,0,0,0,0,0,1,0,0,0,0,0,0\n"); },
               "handeye --motions " + csv + " --camera-scaled --out " + result, "NaN"});
  c.push_back({"OneMotion", [=] { WriteAll(csv, OneAxisCsv(1)); },
               "handeye --motions " + csv + " --camera-scaled --out " + result, "too_few_motions"});
  c.push_back({"MotionsAboutOneAxis", [=] { WriteAll(csv, OneAxisCsv(8)); },
               "handeye --motions " + csv + " --camera-scaled --out " + result, "observability: rotation_degenerate"});
  c.push_back(
      {"EmptyMotionsFile", [=] { WriteAll(csv, ""); }, "handeye --motions " + csv + " --out " + result, "header"});
  // --- configs ---
  c.push_back({"ConfigOfWrongType", [=] { ConfigWith("c1.yaml", "stationarity", "min_still_s: abc"); },
               calibrate(GoodLog()) + " --config " + In("c1.yaml"), "min_still_s"});
  c.push_back({"ConfigNegativeThreshold", [=] { ConfigWith("c2.yaml", "lidar_icp", "max_range_m: -1"); },
               calibrate(GoodLog()) + " --config " + In("c2.yaml"), "max_range_m"});
  c.push_back({"ConfigNanThreshold", [=] { ConfigWith("c3.yaml", "handeye", "tolerance_rotation_deg: .nan"); },
               calibrate(GoodLog()) + " --config " + In("c3.yaml"), "tolerance_rotation_deg"});
  c.push_back({"ConfigUnknownKey", [=] { ConfigWith("c4.yaml", "camera_frontend", "detection_scael: 0.5"); },
               calibrate(GoodLog()) + " --config " + In("c4.yaml"), "detection_scael"});
  c.push_back({"ConfigUnknownTopLevelKey", [=] { ConfigWith("c5.yaml", "", "stations_form: log"); },
               calibrate(GoodLog()) + " --config " + In("c5.yaml"), "stations_form"});
  c.push_back({"ConfigNotYaml", [=] { WriteAll(In("c6.yaml"), std::string("\x01\x02{[: ::\n\t- ]\0", 14)); },
               calibrate(GoodLog()) + " --config " + In("c6.yaml"), "c6.yaml"});
  c.push_back({"ConfigMissing", [] {}, calibrate(GoodLog()) + " --config " + In("absent.yaml"), "absent.yaml"});
  c.push_back(
      {"LiveWithoutSpeed", [] {}, "run --log " + GoodLog() + " --live --speed 0 --out " + In("live"), "--live"});
  // --- scenarios and result files ---
  c.push_back({"ScenarioWithUnknownKey",
               [=] {
                 std::string s = ReadAll(kScenarios + "/tiny-equirect.yaml") + "\nweather: rainy\n";
                 WriteAll(In("scenario.yaml"), s);
               },
               "simulate --scenario " + In("scenario.yaml") + " --out " + In("sim.lcmlog"), "weather"});
  c.push_back({"ResultFileNotYaml", [=] { WriteAll(In("result.yaml"), "T_camera_lidar: [1, 2\n"); },
               "evaluate --result " + In("result.yaml") + " --truth " + GoodLog(), "result.yaml"});
  c.push_back({"ExportToUnknownFormat", [=] { WriteAll(In("result.yaml"), ""); },
               "export " + In("result.yaml") + " --format sdf", "sdf"});
  return c;
}

// Numbers at the edge of the command line, and outputs that must not be replaced.
std::vector<BadCase> EdgeCases() {
  std::vector<BadCase> c;
  c.push_back({"RunSpeedNan", [] {}, "run --log " + GoodLog() + " --live --speed nan --out " + In("nan"), "--speed"});
  c.push_back({"RunStagesEmpty", [] {}, "run --log " + GoodLog() + " --stages '' --out " + In("empty"), "--stages"});
  const std::string sim = "simulate --scenario " + kScenarios + "/tiny-equirect.yaml --stations-only --out ";
  c.push_back(
      {"SimulateOntoADirectory", [] { mkdir(In("a-dir").c_str(), 0755); }, sim + In("a-dir"), "a-dir is a directory"});
  const std::string good_result = "T_camera_lidar: [1, 0, 0, 0.1, 0, 1, 0, 0.2, 0, 0, 1, 0.3, 0, 0, 0, 1]\n";
  const auto evaluate = "evaluate --result " + In("good-result.yaml") + " --truth " + In("truth.yaml");
  const std::pair<const char*, const char*> truths[] = {
      {"EvaluateAgainstATruthThatIsNotARotation", "[2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]"},
      {"EvaluateAgainstAZeroTruth", "[0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]"},
      {"EvaluateAgainstANanTruth", "[.nan, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]"}};
  for (const auto& [name, matrix] : truths)
    c.push_back({name,
                 [=, m = std::string(matrix)] {
                   WriteAll(In("good-result.yaml"), good_result);
                   WriteAll(In("truth.yaml"), "T_camera_lidar: " + m + "\n");
                 },
                 evaluate, "truth.yaml"});
  c.push_back({"DoctorUnknownScheme", [] {}, "doctor --bus 'foo://x'", "unknown transport 'foo'"});
  c.push_back({"DoctorNoScheme", [] {}, "doctor --bus nothing", "has no scheme"});
  c.push_back({"DoctorTtlOutOfRange", [] {}, "doctor --bus 'udpm://239.255.76.67:7699?ttl=999'", "ttl=999"});
  c.push_back({"DoctorNegativeReceiveBuffer", [] {}, "doctor --bus 'udpm://239.255.76.67:7699?ttl=0&recv_buf_size=-1'",
               "recv_buf_size=-1"});
  c.push_back({"DoctorSaysWhatItDidNotTest", [] {}, "doctor --bus 'file:///tmp/absent.lcmlog'", "not tested", false});
  for (const char* format : {"json", "kitti", "ros-static-tf"})
    c.push_back({std::string("ExportToAFullDisk_") + (format[0] == 'r' ? "ros_static_tf" : format),
                 [=] { WriteAll(In("good-result.yaml"), good_result); },
                 "export " + In("good-result.yaml") + " --format " + format + " --out /dev/full", "/dev/full"});
  c.push_back(
      {"SimulateOntoAPipe", [] { mkfifo(In("a-pipe").c_str(), 0644); }, sim + In("a-pipe"), "a-pipe is a pipe"});
  return c;
}

// A copy of the good log whose stations all say the camera is `width` pixels wide (the images unchanged).
std::string LogWithCameraWidth(const std::string& name, int width) {
  const std::string path = In(name);
  LogReader reader(GoodLog());
  LogWriter writer(path);
  while (auto e = reader.Next()) {
    if (e->channel == "STATION") {
      station_t station;
      if (station.decode(e->data.data(), 0, static_cast<int>(e->data.size())) < 0) continue;
      station.camera.width = width;
      std::vector<uint8_t> bytes(static_cast<size_t>(station.getEncodedSize()));
      station.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      writer.Write(e->channel, e->utime, bytes.data(), bytes.size());
    } else {
      writer.Write(e->channel, e->utime, e->data.data(), e->data.size());
    }
  }
  return path;
}

// YAML read strictly: a key given twice or a quote left open is an error with file and line, in every
// kind of YAML file the project reads.
std::vector<BadCase> StrictYamlCases() {
  std::vector<BadCase> c;
  const std::string calibrate = "calibrate --log " + GoodLog() + " --out " + In("yaml-out") + " --config ";
  c.push_back({"ConfigKeyGivenTwice", [] { ConfigWith("d1.yaml", "", "stations_from: log\nstations_from: detector"); },
               calibrate + In("d1.yaml"), "duplicate key 'stations_from'"});
  c.push_back({"ConfigSectionKeyGivenTwice",
               [] { ConfigWith("d2.yaml", "handeye", "max_iterations: 5\n  max_iterations: 9"); },
               calibrate + In("d2.yaml"), "duplicate key 'max_iterations'"});
  c.push_back({"ConfigQuoteLeftOpen", [] { ConfigWith("d3.yaml", "", "note: \"unfinished"); },
               calibrate + In("d3.yaml"), "never closed"});
  c.push_back({"ConfigIsADirectory", [] { mkdir(In("config-dir").c_str(), 0755); }, calibrate + In("config-dir"),
               "config-dir: is a directory"});
  const std::string camera_motion = "camera-motion " + In("good.png") + " " + In("good.png") + " --camera ";
  auto textured = [] {
    cv::Mat image(128, 256, CV_8UC1);
    cv::randu(image, 0, 255);
    cv::imwrite(In("good.png"), image);
  };
  c.push_back({"CameraKeyGivenTwice",
               [=] {
                 textured();
                 WriteAll(In("d-cam.yaml"), std::string(kPanoramaCamera) + "width: 512\n");
               },
               camera_motion + In("d-cam.yaml"), "d-cam.yaml:4: duplicate key 'width' (first at line 2)"});
  c.push_back({"CameraQuoteLeftOpen",
               [=] {
                 textured();
                 WriteAll(In("q-cam.yaml"), "model: 'equirectangular\nwidth: 256\nheight: 128\n");
               },
               camera_motion + In("q-cam.yaml"), "q-cam.yaml:1: a quoted value opens here and is never closed"});
  const std::string matrix = "T_camera_lidar: [1, 0, 0, 0.1, 0, 1, 0, 0.2, 0, 0, 1, 0.3, 0, 0, 0, 1]\n";
  c.push_back({"ResultKeyGivenTwice", [=] { WriteAll(In("d-result.yaml"), matrix + "status: converged\n" + matrix); },
               "export " + In("d-result.yaml") + " --format json", "duplicate key 'T_camera_lidar'"});
  c.push_back({"ResultQuoteLeftOpen", [=] { WriteAll(In("q-result.yaml"), "status: \"converged\n" + matrix); },
               "export " + In("q-result.yaml") + " --format kitti", "never closed"});
  c.push_back({"TruthKeyGivenTwice",
               [=] {
                 WriteAll(In("good-result.yaml"), matrix);
                 WriteAll(In("d-truth.yaml"), matrix + matrix);
               },
               "evaluate --result " + In("good-result.yaml") + " --truth " + In("d-truth.yaml"),
               "d-truth.yaml:2: duplicate key"});
  c.push_back(
      {"ScenarioKeyGivenTwice",
       [] { WriteAll(In("d-scenario.yaml"), ReadAll(kScenarios + "/tiny-equirect.yaml") + "\nseed: 1\nseed: 2\n"); },
       "simulate --scenario " + In("d-scenario.yaml") + " --out " + In("d-sim.lcmlog"), "duplicate key 'seed'"});
  return c;
}

// Bus URLs: one parser, before any process starts; every option with its range.
std::vector<BadCase> BusUrlCases() {
  std::vector<BadCase> c;
  const std::string run = "run --log " + GoodLog() + " --out " + In("url-out") + " --bus ";
  c.push_back({"RunIoxMaxNotANumber", [] {}, run + "'iox://?max=banana'", "max=banana is not an integer"});
  c.push_back({"RunIoxDepthOutOfRange", [] {}, run + "'iox://?depth=100000'", "depth=100000"});
  c.push_back({"RunTtlOutOfRange", [] {}, run + "'udpm://239.255.76.67:7699?ttl=999'", "ttl=999"});
  c.push_back(
      {"RunReceiveBufferNegative", [] {}, run + "'udpm://239.255.76.67:7699?recv_buf_size=-1'", "recv_buf_size=-1"});
  c.push_back({"RunUdpmWithoutPort", [] {}, run + "'udpm://239.255.76.67'", "GROUP:PORT"});
  c.push_back({"RunDdsUnknownOption", [] {}, run + "'dds://?domian=3'", "unknown parameter 'domian'"});
  c.push_back({"RunDdsDomainOutOfRange", [] {}, run + "'dds://?domain=300'", "domain=300"});
  c.push_back({"RunDdsWithAnAddress", [] {}, run + "'dds://10.0.0.1'", "takes no address"});
  c.push_back({"RunUnknownScheme", [] {}, run + "'zmq://localhost'", "unknown transport 'zmq'"});
  c.push_back({"ConfigBusUrlOutOfRange",
               [] {
                 std::string text = ReadAll(kConfig);
                 const size_t at = text.find("\n  # url: ");  // the shipped config leaves the bus unset
                 text.replace(at + 1, text.find('\n', at + 1) - at - 1, "  url: 'dds://?depth=0'");
                 WriteAll(In("bus.yaml"), text);
               },
               "run --log " + GoodLog() + " --out " + In("url-out") + " --config " + In("bus.yaml"), "depth=0"});
  c.push_back({"DoctorIoxMaxNotANumber", [] {}, "doctor --bus 'iox://?max=banana'", "max=banana"});
  c.push_back({"DoctorMemqWithOptions", [] {}, "doctor --bus 'memq://?ttl=1'", "unknown parameter 'ttl'"});
  return c;
}

// Outputs: written and checked after flush and close; a camera a stage cannot use says why.
std::vector<BadCase> OutputAndSizeCases() {
  std::vector<BadCase> c;
  c.push_back({"HandeyeResultToAFullDisk", [] { WriteAll(In("motions.csv"), OneAxisCsv(8)); },
               "handeye --motions " + In("motions.csv") + " --camera-scaled --out /dev/full", "/dev/full"});
  c.push_back({"ImportOntoADirectory",
               [] {
                 mkdir(In("import-dir").c_str(), 0755);
                 mkdir(In("pairs").c_str(), 0755);
                 WriteBin(In("pairs/0001.bin"), BoxCloud());
                 cv::Mat textured(128, 256, CV_8UC1);
                 cv::randu(textured, 0, 255);
                 cv::imwrite(In("pairs/0001.png"), textured);
                 WriteCamera(In("pairs-camera.yaml"), kPanoramaCamera);
               },
               "import folder " + In("pairs") + " --camera " + In("pairs-camera.yaml") + " --out " + In("import-dir"),
               "import-dir is a directory"});
  c.push_back({"StationsWithACameraWiderThanItsImages", [] { LogWithCameraWidth("wide-camera.lcmlog", 100000); },
               "calibrate --log " + In("wide-camera.lcmlog") + " --out " + In("wide-out"),
               "failed motions: CAMERA_MOTION: image i: image is 512x256 but the camera model expects 100000x256"});
  c.push_back(
      {"RunSpeedNegative", [] {}, "run --log " + GoodLog() + " --live --speed -2 --out " + In("neg"), "--speed"});
  c.push_back(
      {"RunSpeedInfinite", [] {}, "run --log " + GoodLog() + " --live --speed inf --out " + In("inf"), "--speed"});
  return c;
}

// The pipeline's own config with one piece of text replaced.
void ConfigReplacing(const std::string& name, const std::string& from, const std::string& to) {
  std::string text = ReadAll(kConfig);
  const size_t at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("the shipped config has no '" + from + "' to replace");
  text.replace(at, from.size(), to);
  WriteAll(In(name), text);
}

// A live ROS 2 robot: flags that cannot go together, ROS 2 settings out of range, a file that is not a bag.
std::vector<BadCase> Ros2Cases() {
  std::vector<BadCase> c;
  c.push_back({"RunRos2WithALog", [] {}, "run --ros2 --log " + GoodLog() + " --out " + In("ros2-log"),
               "--ros2 takes the sensors from a running ROS 2 robot"});
  c.push_back({"Ros2InputTopicWithASpace",
               [] { ConfigReplacing("r1.yaml", "image_topic: /camera/image_raw", "image_topic: \"/camera image\""); },
               "run --ros2 --config " + In("r1.yaml") + " --out " + In("r1"), "has a character ROS does not allow"});
  c.push_back(
      {"Ros2InputDomainOutOfRange", [] { ConfigReplacing("r2.yaml", "ros2_input:\n", "ros2_input:\n  domain: 500\n"); },
       "run --ros2 --config " + In("r2.yaml") + " --out " + In("r2"), "'ros2_input.domain' must be in [0, 232]"});
  c.push_back({"DoctorRos2WithABadConfig",
               [] { ConfigReplacing("r3.yaml", "topic_timeout_s: 15", "topic_timeout_s: -1"); },
               "doctor --ros2 --config " + In("r3.yaml"), "topic_timeout_s"});
  c.push_back(
      {"Ros2TfOverlayTopicWithASpace",
       [] { ConfigReplacing("r4.yaml", "overlay_topic: /fusecal/overlay", "overlay_topic: \"/fusecal/over lay\""); },
       "run --ros2 --config " + In("r4.yaml") + " --out " + In("r4"), "overlay_topic"});
  c.push_back({"ImportRosbagMcapThatIsText", [] { WriteAll(In("text.mcap"), "not a bag at all\n"); },
               "import rosbag " + In("text.mcap") + " --image-topic /a --cloud-topic /b --out " + In("text.lcmlog"),
               "not an MCAP file (no MCAP magic) at offset 0"});
  c.push_back({"ImportRosbagDb3ThatIsText", [] { WriteAll(In("text.db3"), "not a database\n"); },
               "import rosbag " + In("text.db3") + " --image-topic /a --cloud-topic /b --out " + In("text2.lcmlog"),
               "text.db3"});
  return c;
}

std::vector<BadCase> AllCases() {
  std::vector<BadCase> all = Cases();
  for (auto& c : EdgeCases()) all.push_back(std::move(c));
  for (auto& c : StrictYamlCases()) all.push_back(std::move(c));
  for (auto& c : BusUrlCases()) all.push_back(std::move(c));
  for (auto& c : OutputAndSizeCases()) all.push_back(std::move(c));
  for (auto& c : Ros2Cases()) all.push_back(std::move(c));
  return all;
}

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ClearErrorNamingTheInputAndNoCrashNoConvergence) {
  const BadCase& c = GetParam();
  ASSERT_FALSE(GoodLog().empty());
  c.make();
  const auto r = RunCommand("timeout 120 " + kFusecal + " " + c.command + " 2>&1");
  EXPECT_GE(r.exit_code, c.fails ? 1 : 0) << c.command << "\n" << r.output;
  EXPECT_LE(r.exit_code, 123) << "crashed or hung (timeout: 124, signal: 128+N): " << c.command << "\n" << r.output;
  EXPECT_NE(r.output.find(c.names), std::string::npos) << "the error does not say '" << c.names << "'\n" << r.output;
  if (!c.fails) return;
  EXPECT_EQ(r.output.find("result: converged"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("status: converged"), std::string::npos) << r.output;
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInput, ::testing::ValuesIn(AllCases()),
                         [](const ::testing::TestParamInfo<BadCase>& info) { return info.param.name; });

// Identical scans are not an error: the motion between them is the identity.
TEST(BadInputBoundaries, IdenticalScansRegisterToTheIdentity) {
  const std::string scan = In("same.bin");
  WriteBin(scan, BoxCloud());
  const auto r = RunCommand("timeout 120 " + kFusecal + " register " + scan + " " + scan + " 2>&1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_TRUE(j["converged"].get<bool>()) << r.output;
  const std::vector<double> T = j["T_a_b"].get<std::vector<double>>();
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(T[k], k % 5 == 0 ? 1.0 : 0.0, 1e-5) << "element " << k << ": " << r.output;
}

}  // namespace
}  // namespace fusecal
