// The fuzz entries: one function per decoder of bus or file input, each taking the raw bytes the way the
// program would receive them (an LCM message, a log file, a DDS sample, a YAML file, a scan file, ...).
//
// An entry returns 0 whatever the bytes. A decoder that rejects them with an exception derived from
// std::exception (carrying a message) has done its job; everything else is a finding: a crash, a
// sanitizer report, an uncaught exception of another type, a hang or a leak. libFuzzer calls one entry
// per executable (libfuzzer_main.cpp, fuzz_<name>); test_fuzz_replay.cpp replays the seed corpus and
// every crash once found (tests/fuzz/corpus, tests/fuzz/regressions) through the same entries.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fusecal::fuzz {

// lcmtypes (entries_lcmtypes.cpp): DecodeMessage<T> as Bus::Subscribe does, the JSON view of
// `fusecal log dump`, and the conversion the stages apply to the decoded message.
int FuzzOneLcmCameraInfo(const uint8_t* data, size_t size);
int FuzzOneLcmExtrinsic(const uint8_t* data, size_t size);
int FuzzOneLcmGroundTruth(const uint8_t* data, size_t size);
int FuzzOneLcmImage(const uint8_t* data, size_t size);
int FuzzOneLcmMotionSet(const uint8_t* data, size_t size);
int FuzzOneLcmMotion(const uint8_t* data, size_t size);
int FuzzOneLcmPointCloud(const uint8_t* data, size_t size);
int FuzzOneLcmStation(const uint8_t* data, size_t size);
int FuzzOneLcmStatus(const uint8_t* data, size_t size);

// Logs (entries_logs.cpp): the LCM log reader with every event decoded as `fusecal log dump` does; the
// reference extrinsic of a log (GROUND_TRUTH).
int FuzzOneLcmLog(const uint8_t* data, size_t size);
int FuzzOneGroundTruthLog(const uint8_t* data, size_t size);

// The DDS envelope (entries_dds.cpp, with Cyclone DDS only): a serialized fusecal::lcm_message sample
// (4-byte encapsulation header and CDR), checked and read as Cyclone does on receipt, then the channel
// and sequence number handled as DdsBus does.
int FuzzOneDdsEnvelope(const uint8_t* data, size_t size);

// The iox:// chunk (entries_iox.cpp, with iceoryx only): the user payload of one iceoryx chunk (header and
// LCM bytes), checked and handed on as IoxBus does.
int FuzzOneIoxChunk(const uint8_t* data, size_t size);

// YAML (entries_yaml.cpp): the pipeline config with every stage's settings, a simulator scenario, the
// result file, the camera file.
int FuzzOnePipelineConfig(const uint8_t* data, size_t size);
int FuzzOneScenario(const uint8_t* data, size_t size);
int FuzzOneResultFile(const uint8_t* data, size_t size);
int FuzzOneCameraFile(const uint8_t* data, size_t size);

// Importers and scans (entries_importers.cpp): KITTI calibration (the two files, split at the first
// line "----") and timestamps.txt, PCD, PLY and KITTI .bin scans, the Ishikawa PLY with a pose and its
// motion.txt.
int FuzzOneKittiCalibration(const uint8_t* data, size_t size);
int FuzzOneKittiTimestamps(const uint8_t* data, size_t size);
int FuzzOneScanPcd(const uint8_t* data, size_t size);
int FuzzOneScanPly(const uint8_t* data, size_t size);
int FuzzOneScanBin(const uint8_t* data, size_t size);
int FuzzOnePlyWithPose(const uint8_t* data, size_t size);
int FuzzOneIshikawaMotions(const uint8_t* data, size_t size);

// Texts users type or write by hand (entries_text.cpp): a bus URL (ParseBusUrl), a channel pattern and
// channel names to match (first line the pattern), an extrinsic in an export format (first byte the
// format), any YAML through the strict loader.
int FuzzOneBusUrl(const uint8_t* data, size_t size);
int FuzzOneChannelPattern(const uint8_t* data, size_t size);
int FuzzOneExtrinsicText(const uint8_t* data, size_t size);
int FuzzOneStrictYaml(const uint8_t* data, size_t size);

// ROS 2 sensor messages in CDR (entries_ros_cdr.cpp): the first byte chooses PointCloud2, Image,
// CompressedImage or CameraInfo; decoded and converted as `fusecal import rosbag` does.
int FuzzOneRosCdr(const uint8_t* data, size_t size);

// Livox's CustomMsg (entries_ros_cdr.cpp): the first byte chooses CDR (even) or ROS 1 (odd); decoded
// and converted as `fusecal import rosbag` does.
int FuzzOneRosLivox(const uint8_t* data, size_t size);

// ROS 2 bags (entries_rosbag2.cpp): an MCAP file, scanned and every message read in log-time order.
int FuzzOneMcap(const uint8_t* data, size_t size);

// The motions CSV of `fusecal handeye --motions` (entries_motion_csv.cpp).
int FuzzOneMotionCsv(const uint8_t* data, size_t size);

}  // namespace fusecal::fuzz
