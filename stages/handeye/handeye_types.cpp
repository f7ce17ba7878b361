#include "stages/handeye/handeye_types.hpp"

#include <cmath>
#include <sstream>

namespace fusecal {
namespace {

bool Positive(double v) { return std::isfinite(v) && v > 0.0; }
bool NonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace

std::string HandEyeSettings::Validate() const {
  std::ostringstream e;
  if (!Positive(max_angle_difference_deg))
    e << "max_angle_difference_deg must be > 0";
  else if (!NonNegative(angle_difference_fraction) || angle_difference_fraction > 1)
    e << "angle_difference_fraction must be in [0, 1]";
  else if (!NonNegative(min_rotation_deg) || min_rotation_deg >= 180.0)
    e << "min_rotation_deg must be in [0, 180)";
  else if (!Positive(orthonormality_tolerance))
    e << "orthonormality_tolerance must be > 0";
  else if (min_pairs < 2)
    e << "min_pairs must be >= 2 (got " << min_pairs << ")";
  else if (!Positive(outlier_factor) || outlier_factor < 1.0)
    e << "outlier_factor must be >= 1";
  else if (!NonNegative(outlier_min_rotation_deg))
    e << "outlier_min_rotation_deg must be >= 0";
  else if (!NonNegative(outlier_min_translation_m))
    e << "outlier_min_translation_m must be >= 0";
  else if (!Positive(robust_loss_scale))
    e << "robust_loss_scale must be > 0";
  else if (!Positive(nominal_rotation_sigma_deg))
    e << "nominal_rotation_sigma_deg must be > 0";
  else if (!Positive(nominal_translation_sigma_m))
    e << "nominal_translation_sigma_m must be > 0";
  else if (!Positive(max_rotation_std_deg))
    e << "max_rotation_std_deg must be > 0";
  else if (!(degenerate_rotation_anisotropy >= 1))
    e << "degenerate_rotation_anisotropy must be >= 1";
  else if (!Positive(max_translation_std_m))
    e << "max_translation_std_m must be > 0";
  else if (!(verdict_hysteresis >= 0 && verdict_hysteresis < 1))
    e << "verdict_hysteresis must be in [0, 1)";
  else if (!shared_camera_errors.Valid() || !shared_lidar_errors.Valid())
    e << "shared error sizes must be >= 0";
  else if (max_iterations < 1)
    e << "max_iterations must be >= 1";
  else if (!NonNegative(function_tolerance) || !NonNegative(parameter_tolerance) || !NonNegative(gradient_tolerance))
    e << "solver tolerances must be >= 0";
  return e.str();
}

bool HandEyeSettings::IsValid(std::string* error) const {
  const std::string e = Validate();
  if (error) *error = e;
  return e.empty();
}

bool HandEyeResult::IsRejected(int station_i, int station_j) const {
  for (const auto& r : rejected_pairs)
    if (r.station_i == station_i && r.station_j == station_j) return true;
  return false;
}

bool HandEyeResult::IsUsed(int station_i, int station_j) const {
  for (const auto& u : used_pairs)
    if (u.station_i == station_i && u.station_j == station_j) return true;
  return false;
}

}  // namespace fusecal
