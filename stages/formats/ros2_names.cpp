#include "stages/formats/ros2_names.hpp"

#include <cctype>
#include <stdexcept>

namespace fusecal {

std::string RosTopicToDds(const std::string& ros_topic) {
  const std::string name = !ros_topic.empty() && ros_topic[0] == '/' ? ros_topic.substr(1) : ros_topic;
  if (name.empty()) throw std::invalid_argument("a ROS 2 topic name must not be empty");
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '/')
      throw std::invalid_argument("ROS 2 topic '" + ros_topic + "' has a character ROS does not allow: '" +
                                  std::string(1, c) + "' (letters, digits, '_' and '/')");
  return "rt/" + name;
}

std::string RosTopicProblem(const std::string& key, const std::string& topic) {
  try {
    RosTopicToDds(topic);
    return {};
  } catch (const std::invalid_argument& e) {
    return key + ": " + e.what();
  }
}

std::string DdsTopicToRos(const std::string& dds_topic) {
  return dds_topic.rfind("rt/", 0) == 0 ? dds_topic.substr(2) : dds_topic;
}

std::string DdsTypeToRos(const std::string& dds_type) {
  const std::string marker = "::dds_::";
  const size_t at = dds_type.find(marker);
  if (at == std::string::npos || dds_type.back() != '_') return dds_type;
  std::string head = dds_type.substr(0, at);  // "sensor_msgs::msg"
  for (size_t p; (p = head.find("::")) != std::string::npos;) head.replace(p, 2, "/");
  return head + "/" + dds_type.substr(at + marker.size(), dds_type.size() - at - marker.size() - 1);
}

std::string RosTypeToDds(const std::string& ros_type) {
  const size_t last = ros_type.rfind('/');
  if (last == std::string::npos) return ros_type;
  std::string head = ros_type.substr(0, last);
  for (size_t p; (p = head.find('/')) != std::string::npos;) head.replace(p, 1, "::");
  return head + "::dds_::" + ros_type.substr(last + 1) + "_";
}

int Ros2DomainFromEnvironment(const char* value, std::string* problem) {
  if (!value || !*value) return 0;
  const std::string text = value;
  size_t used = 0;
  int domain = -1;
  try {
    domain = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || domain < 0 || domain > 232) {
    *problem = "domain: not set, and ROS_DOMAIN_ID='" + text + "' is not an integer in [0, 232]";
    return 0;
  }
  return domain;
}

}  // namespace fusecal
