// A folder of images (png/jpg) and scans (pcd/ply/KITTI bin) paired by file stem; each pair is one
// station. Optional times.csv with lines "stem,seconds" (a header line is allowed).
#pragma once

#include "runtime/io/importers/import_writer.hpp"
#include "stages/foundation/camera_model.hpp"

namespace fusecal {

ImportReport ImportFolder(const std::string& dir, const CameraParams& camera, const std::string& out_log,
                          const ImportProgress& progress = nullptr);

}  // namespace fusecal
