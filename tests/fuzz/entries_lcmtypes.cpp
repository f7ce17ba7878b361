// Fuzz entries of the lcmtypes (fuzz_entries.hpp): the bytes are one LCM-encoded message as it arrives
// on a channel.
#include <string>
#include <vector>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/station_t.hpp"
#include "fusecal/status_t.hpp"
#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/bus.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/extrinsic_status.hpp"
#include "stages/formats/message_json.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::fuzz {

namespace {

// What the stages and tools do with a decoded message of each type.
void Consume(const camera_info_t& m) { CameraFromMsg(m); }
void Consume(const point_cloud_t& m) { CloudFromMsg(m); }
void Consume(const image_t& m) {
  IgnoringRejection([&] { ImageToMat(m); });
  IgnoringRejection([&] { ImageToMatReduced(m, 64); });  // the stationarity detector's quick decode
}
void Consume(const station_t& m) {
  IgnoringRejection([&] { Consume(m.image); });
  IgnoringRejection([&] { Consume(m.cloud); });
  IgnoringRejection([&] { Consume(m.camera); });
}
void Consume(const motion_t& m) {
  IsValidTransform(FromRowMajor(m.T_i_j), 1e-3);
  Matrix6FromArray(m.covariance);
}
void Consume(const motion_set_t& m) {
  for (const motion_t& motion : m.motions) Consume(motion);
}
void Consume(const extrinsic_t& m) {
  ExtrinsicStatusName(m.status);
  ObservabilityName(m.observability);
  for (int j : m.used_station_j) TookMotionTo(m, j);
  IsValidTransform(FromRowMajor(m.T_camera_lidar), 1e-3);
}
void Consume(const status_t&) {}
void Consume(const ground_truth_t& m) {
  IsValidTransform(FromRowMajor(m.T_camera_lidar), 1e-3);
  IgnoringRejection([&] { Consume(m.camera); });
}

template <typename M>
int FuzzOneMessage(const uint8_t* data, size_t size) {
  IgnoringRejection([&] {
    std::string error;
    DecodeToJson(data, size, true, &error);  // `fusecal log dump --full`
  });
  IgnoringRejection([&] {
    M message;
    DecodeMessage(data, size, "FUZZ", &message);  // Bus::Subscribe<M>
    std::vector<uint8_t> encoded(static_cast<size_t>(message.getEncodedSize()));
    message.encode(encoded.data(), 0, static_cast<int>(encoded.size()));  // a recorder or a relay
    Consume(message);
  });
  return 0;
}

}  // namespace

int FuzzOneLcmCameraInfo(const uint8_t* d, size_t n) { return FuzzOneMessage<camera_info_t>(d, n); }
int FuzzOneLcmExtrinsic(const uint8_t* d, size_t n) { return FuzzOneMessage<extrinsic_t>(d, n); }
int FuzzOneLcmGroundTruth(const uint8_t* d, size_t n) { return FuzzOneMessage<ground_truth_t>(d, n); }
int FuzzOneLcmImage(const uint8_t* d, size_t n) { return FuzzOneMessage<image_t>(d, n); }
int FuzzOneLcmMotionSet(const uint8_t* d, size_t n) { return FuzzOneMessage<motion_set_t>(d, n); }
int FuzzOneLcmMotion(const uint8_t* d, size_t n) { return FuzzOneMessage<motion_t>(d, n); }
int FuzzOneLcmPointCloud(const uint8_t* d, size_t n) { return FuzzOneMessage<point_cloud_t>(d, n); }
int FuzzOneLcmStation(const uint8_t* d, size_t n) { return FuzzOneMessage<station_t>(d, n); }
int FuzzOneLcmStatus(const uint8_t* d, size_t n) { return FuzzOneMessage<status_t>(d, n); }

}  // namespace fusecal::fuzz
