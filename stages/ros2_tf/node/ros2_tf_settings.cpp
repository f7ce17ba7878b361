#include "ros2_tf/node/ros2_tf_settings.hpp"

namespace fusecal {

std::string Ros2TfSettings::Validate() const {
  if (domain < 0 || domain > 232) return "domain: must be in [0, 232]";
  if (parent_frame.empty() || child_frame.empty() || parent_frame == child_frame)
    return "parent_frame and child_frame must be two different, non-empty frame ids";
  return {};
}

Ros2TfSettings ReadRos2TfSettings(ConfigReader r) {
  Ros2TfSettings s;
  r.Get("enabled", &s.enabled);
  r.Get("domain", &s.domain);
  r.Get("parent_frame", &s.parent_frame);
  r.Get("child_frame", &s.child_frame);
  r.Finish();
  r.FailIfInvalid(s.Validate());
  return s;
}

}  // namespace fusecal
