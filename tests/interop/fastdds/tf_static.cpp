// `tf-static`: a robot's own tree on rt/tf_static, as tf2_ros's static broadcaster publishes it (reliable,
// transient local, keep last 1), e.g. base_link -> lidar_link, held for late joiners while it runs.
#include <chrono>
#include <cstdio>
#include <thread>

#include "fastdds_domain.hpp"
#include "fastdds_generated/ros2_messagesPubSubTypes.h"
#include "peer_commands.hpp"

namespace fusecal::fastdds_peer {

int TfStatic(int domain_id, const std::string& parent, const std::string& child, double seconds) {
  FastDdsDomain domain(domain_id);
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 1;
  dds::DataWriter* writer = domain.Writer(domain.Topic<tf2_msgs::msg::dds_::TFMessage_PubSubType>("/tf_static"), qos);
  geometry_msgs::msg::dds_::TransformStamped_ transform;
  transform.header_().frame_id_(parent);
  transform.header_().stamp_().sec_(1700000000);
  transform.child_frame_id_(child);
  transform.transform_().translation_().z_(0.8);  // a LiDAR 0.8 m above the base
  transform.transform_().rotation_().w_(1.0);
  tf2_msgs::msg::dds_::TFMessage_ message;
  message.transforms_().push_back(transform);
  if (!writer->write(&message)) throw std::runtime_error("writing rt/tf_static failed");
  std::printf("{\"published\":{\"parent\":\"%s\",\"child\":\"%s\"}}\n", parent.c_str(), child.c_str());
  std::fflush(stdout);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  return 0;
}

}  // namespace fusecal::fastdds_peer
