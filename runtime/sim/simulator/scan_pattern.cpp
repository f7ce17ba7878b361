#include "runtime/sim/simulator/scan_pattern.hpp"

#include <cmath>

#include "runtime/sim/simulator/scenario.hpp"

namespace fusecal::sim {

namespace {

// Prism and swing rates, in turns per second: incommensurate with each other and with any frame rate, so
// that no two frames of a session sample the same directions.
constexpr double kPrismA_hz = 73.1415926;
constexpr double kPrismB_hz = -47.2718281;
constexpr double kAzimuthSweeps_per_frame = 1.0;
constexpr double kSwing_hz = 1419.7320508;

Eigen::Vector3f FromAzimuthElevation(double azimuth, double elevation) {
  const double ce = std::cos(elevation);
  return Eigen::Vector3d(ce * std::cos(azimuth), ce * std::sin(azimuth), std::sin(elevation)).cast<float>();
}

// Equal prisms: the offset reaches the rim (1) when both circles align and passes the centre when they
// oppose.
Eigen::Vector3f RosetteDirection(const LidarParams& p, double t, int line) {
  const double phase = 2.0 * M_PI * line / p.beams;
  const double a = 2.0 * M_PI * kPrismA_hz * t + phase;
  const double b = 2.0 * M_PI * kPrismB_hz * t - phase;
  const double u = 0.5 * (std::cos(a) + std::cos(b)), v = 0.5 * (std::sin(a) + std::sin(b));
  const double half_h = 0.5 * p.field_of_view_deg[0] * M_PI / 180.0;
  const double half_v = 0.5 * p.field_of_view_deg[1] * M_PI / 180.0;
  return FromAzimuthElevation(half_h * u, half_v * v);
}

Eigen::Vector3f PetalDirection(const LidarParams& p, double t, int line) {
  const double phase = 2.0 * M_PI * line / p.beams;
  const double azimuth = M_PI - 2.0 * M_PI * kAzimuthSweeps_per_frame * p.rate_hz * t + phase / 4.0;
  const double top = p.elevation_max_deg * M_PI / 180.0, bottom = p.elevation_min_deg * M_PI / 180.0;
  const double swing = 0.5 * (1.0 + std::sin(2.0 * M_PI * kSwing_hz * t + phase));
  return FromAzimuthElevation(azimuth, bottom + swing * (top - bottom));
}

}  // namespace

std::vector<Eigen::Vector3f> PatternDirections(const LidarParams& params, int frame_index) {
  const int lines = params.beams, columns = params.Columns();
  std::vector<Eigen::Vector3f> out(static_cast<size_t>(lines) * columns);
  const double frame_start = frame_index / params.rate_hz;
  for (int c = 0; c < columns; ++c) {
    const double t = frame_start + c / (columns * params.rate_hz);
    for (int l = 0; l < lines; ++l)
      out[static_cast<size_t>(l) * columns + c] =
          params.model == "rosette" ? RosetteDirection(params, t, l) : PetalDirection(params, t, l);
  }
  return out;
}

}  // namespace fusecal::sim
