// KITTI raw layout: image_02/data/*.png, velodyne_points/data/*.bin, timestamps.txt for each,
// calib_velo_to_cam.txt and calib_cam_to_cam.txt.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/io/importers/import_writer.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

struct KittiCalibration {
  CameraParams camera;       // rectified pinhole of image_02, from P_rect_02 and S_rect_02
  Isometry3 T_camera_lidar;  // camera 2 (rectified) <- Velodyne, through R_rect_00 and P_rect_02
};

// Throws std::runtime_error naming the file and key on a missing or malformed calibration.
KittiCalibration ReadKittiCalibration(const std::string& dir);

// "2011-09-26 13:02:25.964389445" -> microseconds since the epoch (UTC). Throws on bad text.
int64_t ParseKittiTimestamp(const std::string& text);

// A timestamps.txt: one ParseKittiTimestamp line per data file (empty lines skipped). Throws
// std::runtime_error naming the file and line.
std::vector<int64_t> ReadKittiTimestamps(const std::string& path);

struct KittiImportOptions {
  int station_every = 0;  // 0: no stations; N: a STATION every N frames ("every:N")
};

ImportReport ImportKitti(const std::string& dir, const std::string& out_log, const KittiImportOptions& options,
                         const ImportProgress& progress = nullptr);

}  // namespace fusecal
