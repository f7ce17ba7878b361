#include "stages/formats/motion_message.hpp"

#include "stages/formats/conversions.hpp"

namespace fusecal {

motion_t MakeMotion(int station_i, int station_j, const std::string& sensor, const Isometry3& T_i_j, bool scaled,
                    const Matrix6& covariance, int64_t utime) {
  motion_t m{};
  m.utime = utime;
  m.station_i = station_i;
  m.station_j = station_j;
  m.sensor = sensor;
  m.valid = true;
  ToRowMajor(T_i_j, m.T_i_j);
  m.scaled = scaled;
  Matrix6ToArray(covariance, m.covariance);
  m.extrinsic_version = -1;
  return m;
}

motion_t MakeFailedMotion(int station_i, int station_j, const std::string& sensor, const std::string& reason,
                          int64_t utime) {
  motion_t m = MakeMotion(station_i, station_j, sensor, Isometry3::Identity(), false, Matrix6::Identity(), utime);
  m.valid = false;
  m.failure_reason = reason.empty() ? "failed" : reason;
  return m;
}

}  // namespace fusecal
