#include "ros2_tf/ros2_tf_settings.hpp"

namespace fusecal {

Ros2TfSettings ReadRos2TfSettings(ConfigReader r) {
  Ros2TfSettings s;
  r.Get("enabled", &s.enabled);
  r.Get("domain", &s.domain, InRange(0, 232));
  r.Get("parent_frame", &s.parent_frame);
  r.Get("child_frame", &s.child_frame);
  r.Finish();
  if (s.parent_frame.empty() || s.child_frame.empty() || s.parent_frame == s.child_frame)
    r.FailSection("parent_frame and child_frame must be two different, non-empty frame ids");
  return s;
}

}  // namespace fusecal
