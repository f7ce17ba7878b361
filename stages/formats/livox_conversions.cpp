#include "stages/formats/livox_conversions.hpp"

#include <stdexcept>
#include <string>

namespace fusecal {

PointCloud LivoxCustomMsgToPointCloud(const RosLivoxCustomMsg& msg, int* dropped) {
  if (msg.point_num != msg.points.size())
    throw std::runtime_error("CustomMsg point_num is " + std::to_string(msg.point_num) + " but it holds " +
                             std::to_string(msg.points.size()) + " points");
  const bool timed = !msg.header.stamp.IsZero();
  // In unsigned arithmetic, which wraps (a garbled timebase must not overflow): the difference of two
  // times of one clock is small and signed.
  const uint64_t stamp_ns = static_cast<uint64_t>(msg.header.stamp.sec) * 1000000000u + msg.header.stamp.nsec;
  PointCloud cloud;
  cloud.points.reserve(msg.points.size());
  cloud.intensity.reserve(msg.points.size());
  cloud.ring.reserve(msg.points.size());
  if (timed) cloud.time_offset_s.reserve(msg.points.size());
  int skipped = 0;
  for (const RosLivoxPoint& point : msg.points) {
    const Eigen::Vector3f p(point.x, point.y, point.z);
    if (!p.allFinite() || p.squaredNorm() == 0.0f) {
      ++skipped;
      continue;
    }
    cloud.points.push_back(p);
    cloud.intensity.push_back(point.reflectivity);
    cloud.ring.push_back(point.line);
    if (timed) {
      const auto offset_ns = static_cast<int64_t>(msg.timebase + point.offset_time - stamp_ns);
      cloud.time_offset_s.push_back(static_cast<float>(static_cast<double>(offset_ns) * 1e-9));
    }
  }
  if (dropped) *dropped = skipped;
  return cloud;
}

}  // namespace fusecal
