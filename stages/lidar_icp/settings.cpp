#include <cmath>
#include <sstream>

#include "stages/lidar_icp/registration.hpp"

namespace fusecal::lidar_icp {
namespace {

template <typename T>
bool InRange(T v, T lo, T hi) {
  return std::isfinite(static_cast<double>(v)) && v >= lo && v <= hi;
}

}  // namespace

std::string RegistrationSettings::Validate() const {
  std::ostringstream e;
  auto fail = [&](const char* field, const std::string& what) {
    if (e.tellp() > 0) e << "; ";
    e << field << " " << what;
  };
  if (!InRange(min_range_m, 0.0, 1e4)) fail("min_range_m", "must be in [0, 1e4]");
  if (!InRange(max_range_m, 0.0, 1e5) || !(max_range_m > min_range_m))
    fail("max_range_m", "must be finite and greater than min_range_m");
  if (!InRange(voxel_size_m, 0.0, 10.0)) fail("voxel_size_m", "must be in [0, 10] (0 = automatic)");
  if (!InRange(max_source_points, 100, 10000000)) fail("max_source_points", "must be in [100, 1e7]");
  if (!InRange(normal_neighbors, 5, 100)) fail("normal_neighbors", "must be in [5, 100]");
  if (!InRange(min_points, 10, 10000000)) fail("min_points", "must be in [10, 1e7]");
  if (!InRange(max_tilt_deg, 0.0, 180.0)) fail("max_tilt_deg", "must be in [0, 180]");
  if (!InRange(rotation_step_deg, 1.0, 45.0)) fail("rotation_step_deg", "must be in [1, 45]");
  if (!InRange(global_candidates, 1, 100)) fail("global_candidates", "must be in [1, 100]");
  if (!InRange(global_sample_points, 100, 1000000)) fail("global_sample_points", "must be in [100, 1e6]");
  if (!InRange(max_correspondence_m, 0.0, 100.0)) fail("max_correspondence_m", "must be in [0, 100] (0 = automatic)");
  if (!InRange(min_correspondence_m, 0.0, 100.0)) fail("min_correspondence_m", "must be in [0, 100] (0 = automatic)");
  if (max_correspondence_m > 0 && min_correspondence_m > max_correspondence_m)
    fail("min_correspondence_m", "must not exceed max_correspondence_m");
  if (!InRange(threshold_shrink, 0.05, 0.95)) fail("threshold_shrink", "must be in [0.05, 0.95]");
  if (!InRange(max_iterations_per_level, 1, 1000)) fail("max_iterations_per_level", "must be in [1, 1000]");
  if (!InRange(convergence_rotation_rad, 1e-12, 0.1) || !(convergence_rotation_rad > 0))
    fail("convergence_rotation_rad", "must be in (0, 0.1]");
  if (!InRange(convergence_translation_m, 1e-12, 1.0) || !(convergence_translation_m > 0))
    fail("convergence_translation_m", "must be in (0, 1]");
  if (!InRange(min_fitness, 0.0, 1.0)) fail("min_fitness", "must be in [0, 1]");
  if (!InRange(max_free_space_violation, 0.0, 1.0)) fail("max_free_space_violation", "must be in [0, 1]");
  if (!InRange(min_conditioning, 0.0, 1.0)) fail("min_conditioning", "must be in [0, 1]");
  if (!InRange(num_threads, 0, 1024)) fail("num_threads", "must be in [0, 1024] (0 = all)");
  return e.str();
}

}  // namespace fusecal::lidar_icp
