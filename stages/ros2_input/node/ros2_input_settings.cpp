#include "stages/ros2_input/node/ros2_input_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "stages/formats/ros2_names.hpp"

namespace fusecal {

bool Ros2CameraTopics::compressed() const {
  const std::string suffix = "/compressed";
  return image_topic.size() > suffix.size() &&
         image_topic.compare(image_topic.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// image_transport's layout: /cam/image_raw and /cam/image_raw/compressed have /cam/camera_info.
std::string Ros2CameraTopics::CameraInfoTopic() const {
  if (!camera_info_topic.empty()) return camera_info_topic;
  std::string base = compressed() ? image_topic.substr(0, image_topic.size() - 11) : image_topic;
  const size_t slash = base.rfind('/');
  return (slash == std::string::npos ? std::string() : base.substr(0, slash)) + "/camera_info";
}

bool Ros2InputSettings::compressed() const { return CameraTopics().front().compressed(); }
std::string Ros2InputSettings::CameraInfoTopic() const { return CameraTopics().front().CameraInfoTopic(); }

std::vector<Ros2CameraTopics> Ros2InputSettings::CameraTopics() const {
  if (rig_cameras.front().empty()) return {Ros2CameraTopics{"", image_topic, camera_info_topic, camera_file}};
  std::vector<Ros2CameraTopics> topics;
  for (const auto& name : rig_cameras)
    for (const auto& c : cameras)
      if (c.name == name) topics.push_back(c);
  return topics;
}

std::string Ros2InputSettings::RigProblem() const {
  if (rig_cameras.front().empty())
    return cameras.empty() ? "" : "cameras: the rig has one camera without a name (set image_topic instead)";
  for (const auto& name : rig_cameras) {
    const auto n =
        std::count_if(cameras.begin(), cameras.end(), [&](const Ros2CameraTopics& c) { return c.name == name; });
    if (n != 1)
      return "cameras: camera " + name + (n ? " is listed twice" : " of the rig has no image_topic here") +
             " (ros2_input.cameras: [{name: " + name + ", image_topic: /" + name + "/image_raw}, ...])";
  }
  for (const auto& c : cameras)
    if (std::find(rig_cameras.begin(), rig_cameras.end(), c.name) == rig_cameras.end())
      return "cameras: " + c.name + " is not a camera of the rig";
  return "";
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
  for (ConfigReader& item : r.Items("cameras")) {
    Ros2CameraTopics c;
    item.Require("name", &c.name);
    item.Require<std::string>("image_topic", &c.image_topic,
                              [](const std::string& t) { return RosTopicProblem("image_topic", t); });
    item.Get<std::string>("camera_info_topic", &c.camera_info_topic, [](const std::string& t) {
      return t.empty() ? std::string() : RosTopicProblem("camera_info_topic", t);
    });
    item.Get("camera_file", &c.camera_file);
    item.Finish();
    if (c.image_topic == s.cloud_topic) item.Fail("image_topic", "must differ from cloud_topic");
    s.cameras.push_back(c);
  }
  r.Finish();
  r.FailIfInvalid(domain_problem);
  r.FailIfInvalid(s.Validate());
  return s;
}

}  // namespace fusecal
