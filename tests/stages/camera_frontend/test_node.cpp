// The camera front end's node on a rig of several cameras: it takes its own camera's stations and
// answers on its own channel; a station whose image is too small to track is answered with a failed
// motion that says so, and one whose image cannot be read raises an error naming the camera and station.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

#include "fusecal/motion_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/channels.hpp"
#include "stages/camera_frontend/node/camera_frontend_node.hpp"
#include "stages/formats/conversions.hpp"

using namespace fusecal;

namespace {

station_t StationOf(int id, const std::string& camera, int side) {
  CameraParams params;
  params.model = "pinhole";
  params.width = params.height = side;
  params.fx = params.fy = side;
  params.cx = params.cy = side / 2.0;
  station_t s{};
  s.id = id;
  s.utime = 1000000 * (id + 1);
  s.camera = CameraToMsg(params, s.utime);
  s.camera.name = camera;
  cv::Mat texture(side, side, CV_8U);
  cv::theRNG().state = 7;
  cv::randu(texture, 0, 255);
  s.image = MatToImage(texture, "mono8", s.utime);
  return s;
}

}  // namespace

TEST(CameraFrontendNode, ACameraOfARigTakesItsOwnStationsAndNamesItselfInErrors) {
  CameraFrontendNodeSettings settings;
  settings.camera = "left";
  CameraFrontendNode node(settings);
  auto bus = MakeBus("memq://");
  std::vector<motion_t> left, plain;
  auto a = bus->Subscribe(ForCamera(channels::kCameraMotion, "left"), [&](const motion_t& m) { left.push_back(m); });
  auto b = bus->Subscribe(channels::kCameraMotion, [&](const motion_t& m) { plain.push_back(m); });
  node.Start(*bus);
  // Too small to track: the motion from it fails and says so, on this camera's channel.
  bus->Publish(ForCamera(channels::kStation, "left"), StationOf(0, "left", 1));
  bus->Publish(channels::kStation, StationOf(0, "", 64));  // another rig's plain channel: not this node's
  while (bus->Handle(0) > 0) {
  }
  bus->Publish(ForCamera(channels::kStation, "left"), StationOf(1, "left", 64));
  while (bus->Handle(0) > 0) {
  }
  ASSERT_EQ(left.size(), 1u);
  EXPECT_FALSE(left[0].valid);
  EXPECT_EQ(left[0].station_j, 1);
  EXPECT_NE(left[0].failure_reason.find("image i: image is 1x1, too small to track"), std::string::npos)
      << left[0].failure_reason;
  // An image that cannot be read: the error names the camera and the station; the station is answered.
  station_t odd = StationOf(2, "left", 64);
  odd.image.encoding = "yuv422";
  bus->Publish(ForCamera(channels::kStation, "left"), odd);
  std::string error;
  try {
    while (bus->Handle(0) > 0) {
    }
  } catch (const std::exception& e) {
    error = e.what();
  }
  EXPECT_EQ(error.rfind("camera left, station 2: ", 0), 0u) << error;
  EXPECT_NE(error.find("yuv422"), std::string::npos) << error;
  while (bus->Handle(0) > 0) {
  }
  ASSERT_EQ(left.size(), 2u);  // answered, failed, so that nobody waits for it
  EXPECT_FALSE(left[1].valid);
  EXPECT_EQ(left[1].station_j, 2);
  EXPECT_TRUE(plain.empty());
}
