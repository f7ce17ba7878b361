#include "stages/ros2_tf/node/ros2_tf_settings.hpp"

#include <cstdlib>

#include "stages/formats/ros2_names.hpp"

namespace fusecal {

std::string Ros2TfSettings::Validate() const {
  if (domain < 0 || domain > 232) return "domain: must be in [0, 232]";
  if (!parent_frame.empty() && parent_frame == child_frame)
    return "parent_frame and child_frame must be two different frame ids";
  if (!overlay_topic.empty()) return RosTopicProblem("overlay_topic", overlay_topic);
  return {};
}

Ros2TfSettings ReadRos2TfSettings(ConfigReader r) {
  Ros2TfSettings s;
  r.Get("enabled", &s.enabled);
  std::string domain_problem;
  if (!r.Has("domain")) s.domain = Ros2DomainFromEnvironment(std::getenv("ROS_DOMAIN_ID"), &domain_problem);
  r.Get("domain", &s.domain);
  r.Get("parent_frame", &s.parent_frame);
  r.Get("child_frame", &s.child_frame);
  r.Get("overlay_topic", &s.overlay_topic);
  r.Get("diagnostics", &s.diagnostics);
  r.Finish();
  r.FailIfInvalid(domain_problem);
  r.FailIfInvalid(s.Validate());
  return s;
}

}  // namespace fusecal
