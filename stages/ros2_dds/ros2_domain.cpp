#include "stages/ros2_dds/ros2_domain.hpp"

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <set>
#include <stdexcept>

namespace fusecal {

std::string DdsErrorText(dds_return_t code) { return dds_strretcode(code < 0 ? -code : code); }

dds_entity_t JoinRos2Domain(int domain, size_t receive_buffer_bytes) {
  if (domain < 0 || domain > 232)
    throw std::runtime_error("ROS 2 domain " + std::to_string(domain) + " is not in [0, 232]");
  static std::mutex mutex;
  static std::set<int> created;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!created.count(domain)) {
      std::string xml = "<CycloneDDS><Domain id=\"any\"><Internal><SocketReceiveBufferSize min=\"default\" max=\"" +
                        std::to_string(receive_buffer_bytes) + "B\"/></Internal></Domain></CycloneDDS>";
      if (const char* env = std::getenv("CYCLONEDDS_URI"); env && *env) xml += std::string(",") + env;
      const dds_entity_t created_domain = dds_create_domain(static_cast<dds_domainid_t>(domain), xml.c_str());
      // PRECONDITION_NOT_MET: this process already has the domain (a dds:// bus on the same id).
      if (created_domain < 0 && created_domain != DDS_RETCODE_PRECONDITION_NOT_MET)
        throw std::runtime_error("cannot create ROS 2 domain " + std::to_string(domain) + ": " +
                                 DdsErrorText(created_domain));
      created.insert(domain);
    }
  }
  const dds_entity_t participant = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
  if (participant < 0)
    throw std::runtime_error("cannot join ROS 2 domain " + std::to_string(domain) + ": " + DdsErrorText(participant));
  return participant;
}

Ros2Discovery::Ros2Discovery(dds_entity_t participant)
    : reader_(dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr)) {
  if (reader_ < 0) throw std::runtime_error("cannot read DDS discovery (DCPSPublication): " + DdsErrorText(reader_));
}

std::vector<Ros2TopicSeen> Ros2Discovery::Publications() const {
  std::set<std::pair<std::string, std::string>> seen;
  constexpr int kBatch = 256;
  void* samples[kBatch] = {};
  dds_sample_info_t infos[kBatch];
  // read, not take: the list stays for the next call; alive writers only.
  const int n = dds_read_mask(reader_, samples, infos, kBatch, kBatch, DDS_ALIVE_INSTANCE_STATE);
  for (int i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    const auto* endpoint = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
    seen.insert({endpoint->topic_name ? endpoint->topic_name : "", endpoint->type_name ? endpoint->type_name : ""});
  }
  if (n > 0) dds_return_loan(reader_, samples, n);
  std::vector<Ros2TopicSeen> out;
  for (const auto& [topic, type] : seen) out.push_back({DdsTopicToRos(topic), DdsTypeToRos(type)});
  std::sort(out.begin(), out.end(), [](const Ros2TopicSeen& a, const Ros2TopicSeen& b) {
    return a.topic != b.topic ? a.topic < b.topic : a.type < b.type;
  });
  return out;
}

}  // namespace fusecal
