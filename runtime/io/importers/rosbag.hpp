// ROS bags into LCM logs (`fusecal import rosbag`): ROS 1 bags (.bag, through Debian's rosbag_storage)
// and ROS 2 bags (a folder with metadata.yaml, an .mcap or a .db3 file; CDR messages), one code path for
// both over a BagSource (bag_source.hpp). Images (sensor_msgs/Image or CompressedImage) become
// CAMERA_IMAGE, clouds (sensor_msgs/PointCloud2 or Livox's CustomMsg) LIDAR_SCAN, each at its header
// stamp; the camera model comes from --camera or the bag's CameraInfo. The log holds no stations: the
// stationarity stage finds the stops, as it does live.
#pragma once

#include <optional>
#include <string>

#include "runtime/io/importers/import_writer.hpp"
#include "stages/foundation/camera_model.hpp"

namespace fusecal {

struct RosbagImportOptions {
  std::string image_topic;             // empty: an error listing the image topics of the bag
  std::string cloud_topic;             // empty: an error listing the cloud topics of the bag
  std::string camera_info_topic;       // empty: camera_info next to the image topic, or the bag's only one
  std::optional<CameraParams> camera;  // from a camera file: used instead of any CameraInfo
};

// Throws std::runtime_error naming the bag and, for a missing or mistyped topic, every topic it has.
ImportReport ImportRosbag(const std::string& bag_path, const std::string& out_log, const RosbagImportOptions& options,
                          const ImportProgress& progress = nullptr);

}  // namespace fusecal
