// `tf-listen`: rt/tf_static read as tf2_ros's static listener on Fast DDS reads it, joining late.
#include <chrono>
#include <cstdio>

#include "fastdds_domain.hpp"
#include "fastdds_generated/ros2_messagesPubSubTypes.h"
#include "peer_commands.hpp"

namespace fusecal::fastdds_peer {

int TfListen(int domain_id, double timeout_s, int count) {
  using Clock = std::chrono::steady_clock;
  FastDdsDomain domain(domain_id);
  dds::DataReader* reader = domain.Reader(domain.Topic<tf2_msgs::msg::dds_::TFMessage_PubSubType>("/tf_static"),
                                          TfStaticReaderQos(), nullptr);
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  int printed = 0;
  while (printed < count) {
    const double left = std::chrono::duration<double>(end - Clock::now()).count();
    if (left <= 0) break;
    if (!reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(std::min(left, 0.2)))) continue;
    tf2_msgs::msg::dds_::TFMessage_ message;
    dds::SampleInfo info;
    while (reader->take_next_sample(&message, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      for (const auto& t : message.transforms_()) {
        const auto& p = t.transform_().translation_();
        const auto& q = t.transform_().rotation_();
        std::printf(
            "{\"parent\":\"%s\",\"child\":\"%s\",\"stamp\":[%d,%u],\"t\":[%.17g,%.17g,%.17g],"
            "\"q\":[%.17g,%.17g,%.17g,%.17g]}\n",
            t.header_().frame_id_().c_str(), t.child_frame_id_().c_str(), t.header_().stamp_().sec_(),
            t.header_().stamp_().nanosec_(), p.x_(), p.y_(), p.z_(), q.x_(), q.y_(), q.z_(), q.w_());
        ++printed;
      }
    }
    std::fflush(stdout);
  }
  if (printed >= count) return 0;
  std::fprintf(stderr, "fastdds_ros2_peer: %d of %d transforms on rt/tf_static in ROS 2 domain %d within %g s\n",
               printed, count, domain_id, timeout_s);
  return 1;
}

}  // namespace fusecal::fastdds_peer
