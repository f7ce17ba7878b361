#include "stages/handeye/node/result_conversion.hpp"

#include <sstream>

#include "stages/formats/conversions.hpp"
#include "stages/formats/extrinsic_status.hpp"

namespace fusecal {

CalibrationResult ToCalibrationResult(const HandEyeResult& r, const std::function<std::string(int, int)>& name_pair) {
  CalibrationResult out;
  out.T_camera_lidar = r.T_camera_lidar;
  out.covariance = r.covariance;
  out.status = Name(r.status);
  out.observability = Name(r.observability);
  for (const auto& p : r.used_pairs) out.motions_used.push_back(name_pair(p.station_i, p.station_j));
  for (const auto& p : r.rejected_pairs)
    out.motions_rejected.push_back(name_pair(p.station_i, p.station_j) + ": " + p.reason);
  out.residual_rms = r.residual_rms_trans_m;
  std::ostringstream rot;
  rot << r.residual_rms_rot_deg;
  out.extra["residual_rms_rotation_deg"] = rot.str();
  out.extra["scaled"] = r.scaled ? "true" : "false";
  if (!r.message.empty()) out.extra["message"] = r.message;
  if (r.unobservable_direction.norm() > 0.5) out.unobservable_direction = r.unobservable_direction;
  return out;
}

extrinsic_t ToExtrinsicMessage(const HandEyeResult& r, int version, int64_t utime) {
  extrinsic_t msg{};
  msg.utime = utime;
  msg.version = version;
  ToRowMajor(r.T_camera_lidar, msg.T_camera_lidar);
  Matrix6ToArray(r.covariance, msg.covariance);
  msg.status = ToExtrinsicStatus(r.status);
  msg.observability = ToExtrinsicObservability(r.observability);
  for (int i = 0; i < 3; ++i) msg.unobservable_direction[i] = r.unobservable_direction[i];
  msg.converged = r.converged;
  msg.scaled = r.scaled;
  msg.iteration = r.iterations;
  msg.residual_rms = r.residual_rms_trans_m;
  for (const auto& p : r.used_pairs) {
    msg.used_station_i.push_back(p.station_i);
    msg.used_station_j.push_back(p.station_j);
  }
  msg.num_used = static_cast<int32_t>(msg.used_station_i.size());
  for (const auto& p : r.rejected_pairs) {
    msg.rejected_station_i.push_back(p.station_i);
    msg.rejected_station_j.push_back(p.station_j);
  }
  msg.num_rejected = static_cast<int32_t>(msg.rejected_station_i.size());
  msg.message = r.message;
  return msg;
}

}  // namespace fusecal
