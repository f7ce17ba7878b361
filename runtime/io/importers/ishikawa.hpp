// The layout of the paper authors' public dataset (Ishikawa et al.):
//   position<N>.ply  scans; the header holds the station pose as four lines "matrix a b c d", each
//                    line one COLUMN of the 4x4 matrix (T_world_lidar); vertex properties float x y z
//                    plus intensity or confidence
//   position<N>.jpg  equirectangular panoramas taken at the same station. Their convention: z up,
//                    longitude -atan2(y, x), polar angle acos(z / |p|). fusecal's panorama frame
//                    (x right, y down, z forward; camera_model.hpp) relates to theirs by
//                    p_fusecal = R_fusecal_theirs * p_theirs with x = -y_t, y = -z_t, z = x_t, so the
//                    images are used as they are and a result converts with kRotationTheirsFromFusecal.
//   motion.txt       one "a-b" pair per line (1-based station numbers)
// The header poses become GROUND_TRUTH station poses, usable as reference LiDAR motions
// B_ref = T_world_la^-1 * T_world_lb.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "runtime/io/importers/import_writer.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

struct PosedScan {
  PointCloud cloud;
  std::optional<Eigen::Matrix4d> pose;  // from the "matrix" header lines
};

// Reads an ascii or binary PLY whose header may hold "matrix" lines. Throws std::runtime_error naming
// the file on a malformed header or truncated data.
PosedScan ReadPlyWithPose(const std::string& path);

// Rotation from fusecal's panorama frame to the dataset's camera frame (see above).
Eigen::Matrix3d RotationTheirsFromFusecal();

// Station pairs of motion.txt, converted to 0-based station ids.
std::vector<std::pair<int, int>> ReadMotionPairs(const std::string& path);

ImportReport ImportIshikawa(const std::string& dir, const std::string& out_log,
                            const ImportProgress& progress = nullptr);

}  // namespace fusecal
