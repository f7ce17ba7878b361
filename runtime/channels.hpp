// Channel names of the pipeline (docs/design.md section 3). One place, so that nodes, tools and tests agree.
#pragma once

namespace fusecal::channels {

inline constexpr const char* kCameraImage = "CAMERA_IMAGE";    // image_t, raw stream
inline constexpr const char* kLidarScan = "LIDAR_SCAN";        // point_cloud_t, raw stream
inline constexpr const char* kCameraInfo = "CAMERA_INFO";      // camera_info_t
inline constexpr const char* kStation = "STATION";             // station_t
inline constexpr const char* kLidarMotion = "LIDAR_MOTION";    // motion_t, sensor "lidar"
inline constexpr const char* kCameraMotion = "CAMERA_MOTION";  // motion_t, sensor "camera", scaleless
inline constexpr const char* kFusedMotions = "FUSED_MOTIONS";  // motion_set_t, scaled camera motions
inline constexpr const char* kExtrinsic = "EXTRINSIC";         // extrinsic_t
inline constexpr const char* kStatus = "STATUS";               // status_t heartbeat
inline constexpr const char* kGroundTruth = "GROUND_TRUTH";    // ground_truth_t

}  // namespace fusecal::channels
