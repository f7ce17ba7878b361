#include "stages/ros2_input/node/ros2_input_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "stages/formats/ros2_names.hpp"

namespace fusecal {

bool Ros2InputSettings::compressed() const {
  const std::string suffix = "/compressed";
  return image_topic.size() > suffix.size() &&
         image_topic.compare(image_topic.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// image_transport's layout: /cam/image_raw and /cam/image_raw/compressed have /cam/camera_info.
std::string Ros2InputSettings::CameraInfoTopic() const {
  if (!camera_info_topic.empty()) return camera_info_topic;
  std::string base = compressed() ? image_topic.substr(0, image_topic.size() - 11) : image_topic;
  const size_t slash = base.rfind('/');
  return (slash == std::string::npos ? std::string() : base.substr(0, slash)) + "/camera_info";
}

std::string Ros2InputSettings::Validate() const {
  if (domain < 0 || domain > 232) return "domain: must be in [0, 232]";
  for (const auto& [key, topic] :
       {std::pair<const char*, const std::string*>{"image_topic", &image_topic}, {"cloud_topic", &cloud_topic}})
    if (std::string problem = RosTopicProblem(key, *topic); !problem.empty()) return problem;
  if (!camera_info_topic.empty())
    if (std::string problem = RosTopicProblem("camera_info_topic", camera_info_topic); !problem.empty()) return problem;
  if (image_topic == cloud_topic) return "image_topic and cloud_topic must differ";
  if (cloud_type != kPointCloud2Type && cloud_type != kLivoxCustomMsgType)
    return "cloud_type: '" + cloud_type + "' is not " + kPointCloud2Type + " or " + kLivoxCustomMsgType;
  if (!(topic_timeout_s > 0) || !std::isfinite(topic_timeout_s)) return "topic_timeout_s: must be a number > 0";
  if (!(max_message_mb > 0 && max_message_mb <= 1000)) return "max_message_mb: must be in (0, 1000]";
  if (depth < 1 || depth > 100) return "depth: must be in [1, 100]";
  return {};
}

size_t ReceiveBufferBytes(const Ros2InputSettings& settings) {
  return std::max<size_t>(size_t{16} << 20, static_cast<size_t>(6 * settings.max_message_mb * 1e6));
}

Ros2InputSettings ReadRos2InputSettings(ConfigReader r) {
  Ros2InputSettings s;
  std::string domain_problem;
  if (!r.Has("domain")) s.domain = Ros2DomainFromEnvironment(std::getenv("ROS_DOMAIN_ID"), &domain_problem);
  r.Get("domain", &s.domain);
  r.Get("image_topic", &s.image_topic);
  r.Get("cloud_topic", &s.cloud_topic);
  r.Get("cloud_type", &s.cloud_type);
  r.Get("camera_info_topic", &s.camera_info_topic);
  r.Get("camera_file", &s.camera_file);
  r.Get("topic_timeout_s", &s.topic_timeout_s);
  r.Get("max_message_mb", &s.max_message_mb);
  r.Get("depth", &s.depth);
  r.Finish();
  r.FailIfInvalid(domain_problem);
  r.FailIfInvalid(s.Validate());
  return s;
}

}  // namespace fusecal
