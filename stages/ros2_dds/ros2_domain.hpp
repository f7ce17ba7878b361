// A ROS 2 domain joined with Cyclone DDS, as a ROS 2 node would join it: the participant, sized for
// sensor messages of several megabytes sent best effort, and the topics the domain has.
#pragma once

#include <dds/dds.h>

#include <cstddef>
#include <string>
#include <vector>

#include "stages/formats/ros2_names.hpp"

namespace fusecal {

// A participant on ROS 2 domain `domain` (ROS_DOMAIN_ID, 0-232). The domain is created with a socket
// receive buffer of up to `receive_buffer_bytes` (the kernel's net.core.rmem_max caps it: `fusecal
// doctor` checks): Cyclone's default 2 MB loses most best-effort 2.5 MB clouds without counting them.
// $CYCLONEDDS_URI, when set, is applied on top. Throws std::runtime_error naming the domain.
dds_entity_t JoinRos2Domain(int domain, size_t receive_buffer_bytes);

// The writers the participant has discovered on its domain (its own included), as ROS names.
class Ros2Discovery {
 public:
  explicit Ros2Discovery(dds_entity_t participant);
  // Sorted, one entry per (topic, type).
  std::vector<Ros2TopicSeen> Publications() const;

 private:
  dds_entity_t reader_;
};

std::string DdsErrorText(dds_return_t code);

}  // namespace fusecal
