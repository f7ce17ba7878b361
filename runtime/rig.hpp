// The rig's cameras, as the pipeline config's `cameras` names them. Absent: one camera without a name,
// on the plain channels. With names, each camera has its own channels (runtime/channels.hpp) and its own
// camera front end, fusion odometry and hand-eye loop; the stationarity stage decides for the rig and
// LiDAR ICP registers the stations once for every camera (docs/design.md, "Rigs of several cameras").
#pragma once

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "runtime/config_reader.hpp"

namespace fusecal {

struct Rig {
  std::vector<std::string> cameras{""};  // names in config order; {""}: one camera without a name
  std::string camera;                    // the camera of a per-camera stage's process (`--camera`)

  bool named() const { return !cameras.front().empty(); }
  bool Has(const std::string& name) const;
};

// Empty when `name` can name a camera (and end its channels' names), else why not.
std::string CameraNameProblem(const std::string& name);

// The `cameras` list of a pipeline config's root: [{name: front}, {name: left}, ...], at most kMaxCameras.
// Throws ConfigError naming the entry.
std::vector<std::string> ReadRigCameras(ConfigReader& root);
inline constexpr int kMaxCameras = 16;

// Which settings care about the rig, by the field they have for it:
//   camera          a per-camera stage (camera front end, fusion odometry, hand-eye): its camera
//   rig_cameras     the stationarity stage: every camera
//   station_camera  LiDAR ICP: the camera whose stations it registers (the first)
template <typename S, typename = void>
struct IsPerCameraStage : std::false_type {};
template <typename S>
struct IsPerCameraStage<S, std::void_t<decltype(std::declval<S&>().camera = std::string())>> : std::true_type {};
template <typename S, typename = void>
struct TakesRigCameras : std::false_type {};
template <typename S>
struct TakesRigCameras<S, std::void_t<decltype(std::declval<S&>().rig_cameras = std::vector<std::string>())>>
    : std::true_type {};
template <typename S, typename = void>
struct TakesStationCamera : std::false_type {};
template <typename S>
struct TakesStationCamera<S, std::void_t<decltype(std::declval<S&>().station_camera = std::string())>>
    : std::true_type {};

// Gives a stage's settings what they need of the rig.
template <typename Settings>
void ApplyRig(const Rig& rig, Settings* settings) {
  if constexpr (IsPerCameraStage<Settings>::value) settings->camera = rig.camera;
  if constexpr (TakesRigCameras<Settings>::value) settings->rig_cameras = rig.cameras;
  if constexpr (TakesStationCamera<Settings>::value) settings->station_camera = rig.cameras.front();
}

}  // namespace fusecal
