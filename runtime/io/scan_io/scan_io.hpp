// LiDAR scan files <-> fusecal::PointCloud, chosen by extension (case-insensitive):
//   .bin  KITTI Velodyne: float32 x, y, z, reflectance per point, little-endian, no header;
//   .pcd  PCL point cloud data (ascii, binary or binary_compressed; read through PCL);
//   .ply  polygon file format, vertex element (ascii or binary; read through PCL).
// Fields read when present: x y z (required for .pcd/.ply), intensity (or reflectance / i),
// ring, time (float seconds; integer "t" is taken as nanoseconds). Points with NaN are kept: the
// registration core removes them. No PCL type appears in this header.
#pragma once

#include <string>

#include "stages/foundation/point_cloud.hpp"

namespace fusecal {

// Throws std::runtime_error naming the file when it is missing, unreadable, corrupt or truncated (a .bin
// whose size is not a multiple of 16 bytes is truncated), or the extension is not supported.
PointCloud ReadScan(const std::string& path);

// Writes x y z and, when the cloud has them, intensity, ring and time (.bin: x y z intensity, 0 when
// absent). .pcd and .ply are written binary. Throws std::runtime_error naming the file on failure.
void WriteScan(const std::string& path, const PointCloud& cloud);

}  // namespace fusecal
