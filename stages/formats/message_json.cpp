#include "stages/formats/message_json.hpp"

#include "stages/formats/extrinsic_status.hpp"

#include <cstring>
#include <functional>
#include <map>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/station_t.hpp"
#include "fusecal/status_t.hpp"

namespace fusecal {

namespace {

// Bulk arrays appear as {"length": n} unless the caller asks for them in full.
template <typename Vec>
OrderedJson Bulk(const Vec& v, bool full) {
  if (full) return OrderedJson(v);
  return OrderedJson{{"length", v.size()}};
}

template <size_t N>
OrderedJson Fixed(const double (&a)[N]) {
  return OrderedJson(std::vector<double>(a, a + N));
}

OrderedJson ToJson(const image_t& m, bool full) {
  return {{"utime", m.utime}, {"frame_id", m.frame_id}, {"width", m.width}, {"height", m.height},
          {"step", m.step},   {"encoding", m.encoding}, {"size", m.size},   {"data", Bulk(m.data, full)}};
}

OrderedJson ToJson(const point_cloud_t& m, bool full) {
  return {{"utime", m.utime},
          {"frame_id", m.frame_id},
          {"num_points", m.num_points},
          {"x", Bulk(m.x, full)},
          {"y", Bulk(m.y, full)},
          {"z", Bulk(m.z, full)},
          {"intensity", Bulk(m.intensity, full)},
          {"ring", Bulk(m.ring, full)},
          {"time_offset_s", Bulk(m.time_offset_s, full)}};
}

OrderedJson ToJson(const camera_info_t& m, bool) {
  OrderedJson j{{"utime", m.utime}, {"model", m.model}, {"width", m.width}, {"height", m.height},   {"fx", m.fx},
                {"fy", m.fy},       {"cx", m.cx},       {"cy", m.cy},       {"dist", Fixed(m.dist)}};
  if (!m.name.empty()) j["name"] = m.name;  // a camera of a rig of several
  return j;
}

OrderedJson ToJson(const station_t& m, bool full) {
  return {{"utime", m.utime},
          {"id", m.id},
          {"still_from_utime", m.still_from_utime},
          {"still_to_utime", m.still_to_utime},
          {"image", ToJson(m.image, full)},
          {"cloud", ToJson(m.cloud, full)},
          {"camera", ToJson(m.camera, full)}};
}

OrderedJson ToJson(const motion_t& m, bool) {
  return {{"utime", m.utime},           {"station_i", m.station_i}, {"station_j", m.station_j},
          {"sensor", m.sensor},         {"valid", m.valid},         {"failure_reason", m.failure_reason},
          {"T_i_j", Fixed(m.T_i_j)},    {"scaled", m.scaled},       {"covariance", Fixed(m.covariance)},
          {"inliers", m.inliers},       {"fitness", m.fitness},     {"rmse", m.rmse},
          {"iterations", m.iterations}, {"seconds", m.seconds},     {"extrinsic_version", m.extrinsic_version}};
}

OrderedJson ToJson(const motion_set_t& m, bool full) {
  OrderedJson motions = OrderedJson::array();
  for (const auto& motion : m.motions) motions.push_back(ToJson(motion, full));
  return {{"utime", m.utime},
          {"extrinsic_version", m.extrinsic_version},
          {"num_motions", m.num_motions},
          {"motions", motions}};
}

OrderedJson ToJson(const extrinsic_t& m, bool) {
  OrderedJson j{{"utime", m.utime},
                {"version", m.version},
                {"T_camera_lidar", Fixed(m.T_camera_lidar)},
                {"covariance", Fixed(m.covariance)},
                {"status", ExtrinsicStatusName(m.status)},
                {"observability", ObservabilityName(m.observability)},
                {"unobservable_direction", Fixed(m.unobservable_direction)},
                {"converged", m.converged},
                {"scaled", m.scaled},
                {"iteration", m.iteration},
                {"change_rotation_rad", m.change_rotation_rad},
                {"change_translation_m", m.change_translation_m},
                {"residual_rms", m.residual_rms},
                {"num_used", m.num_used},
                {"used_station_i", m.used_station_i},
                {"used_station_j", m.used_station_j},
                {"num_rejected", m.num_rejected},
                {"rejected_station_i", m.rejected_station_i},
                {"rejected_station_j", m.rejected_station_j},
                {"message", m.message},
                {"num_changes", m.num_changes},
                {"change_after_station", m.change_after_station},
                {"change_decided_at_station", m.change_decided_at_station},
                {"change_T_before", m.change_T_before}};
  if (!m.camera.empty()) j["camera"] = m.camera;  // T_<camera>_lidar of a rig of several
  return j;
}

OrderedJson ToJson(const status_t& m, bool) {
  OrderedJson counters = OrderedJson::object();
  for (size_t i = 0; i < m.counter_names.size() && i < m.counter_values.size(); ++i)
    counters[m.counter_names[i]] = m.counter_values[i];
  return {{"utime", m.utime},
          {"name", m.name},
          {"host", m.host},
          {"pid", m.pid},
          {"state", m.state},
          {"counters", counters},
          {"last_error", m.last_error}};
}

OrderedJson ToJson(const ground_truth_t& m, bool full) {
  return {{"utime", m.utime},
          {"source", m.source},
          {"T_camera_lidar", Fixed(m.T_camera_lidar)},
          {"camera", ToJson(m.camera, full)},
          {"num_stations", m.num_stations},
          {"station_id", m.station_id},
          {"T_world_lidar", m.T_world_lidar},
          {"still_from_utime", m.still_from_utime},
          {"still_to_utime", m.still_to_utime}};
}

using Decoder = std::function<std::optional<OrderedJson>(const uint8_t*, size_t, bool)>;

template <typename M>
std::pair<int64_t, std::pair<std::string, Decoder>> Entry() {
  Decoder decode = [](const uint8_t* data, size_t size, bool full) -> std::optional<OrderedJson> {
    M message;
    if (message.decode(data, 0, static_cast<int>(size)) < 0) return std::nullopt;
    return ToJson(message, full);
  };
  return {M::getHash(), {std::string("fusecal.") + M::getTypeName(), decode}};
}

const std::map<int64_t, std::pair<std::string, Decoder>>& Registry() {
  static const std::map<int64_t, std::pair<std::string, Decoder>> registry = {
      Entry<image_t>(),      Entry<point_cloud_t>(), Entry<camera_info_t>(), Entry<station_t>(),     Entry<motion_t>(),
      Entry<motion_set_t>(), Entry<extrinsic_t>(),   Entry<status_t>(),      Entry<ground_truth_t>()};
  return registry;
}

}  // namespace

std::optional<DecodedMessage> DecodeToJson(const uint8_t* data, size_t size, bool full, std::string* error) {
  if (size < 8) {
    *error = "message of " + std::to_string(size) + " bytes is too short for an LCM fingerprint";
    return std::nullopt;
  }
  int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];
  const auto it = Registry().find(hash);
  if (it == Registry().end()) {
    *error = "unknown message type (fingerprint not a fusecal type)";
    return std::nullopt;
  }
  auto json = it->second.second(data, size, full);
  if (!json) {
    *error = "corrupt " + it->second.first + " (" + std::to_string(size) + " bytes do not decode)";
    return std::nullopt;
  }
  return DecodedMessage{it->second.first, std::move(*json)};
}

}  // namespace fusecal
