#include "fastdds_domain.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <memory>
#include <stdexcept>

#include "stages/formats/ros2_names.hpp"

namespace fusecal::fastdds_peer {

using eprosima::fastrtps::types::ReturnCode_t;

namespace {

// Fast DDS's own transports (shared memory and UDPv4 on every interface), sized for samples of several
// MB. Measured with 6.2 MB images and 2.6 MB clouds at 4 Hz: the default 512 KB shared-memory segment
// (the sender's) lost 1 in 10 best-effort samples between two Fast DDS peers, and the default UDP
// receive buffer (the system's, 208 KB) lost most images from a Cyclone DDS writer, reliable or not.
// The kernel caps the buffer at net.core.rmem_max.
void UseTransportsForLargeSamples(dds::DomainParticipantQos& qos) {
  constexpr uint32_t kBytes = 32u << 20;
  auto shm = std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>();
  shm->segment_size(kBytes);
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->receiveBufferSize = kBytes;
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports = {shm, udp};
}

}  // namespace

FastDdsDomain::FastDdsDomain(int domain) {
  if (domain < 0 || domain > 232)
    throw std::runtime_error("ROS 2 domain " + std::to_string(domain) + " is not in [0, 232]");
  dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name("fusecal_fastdds_ros2_peer");
  UseTransportsForLargeSamples(qos);
  participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos);
  if (!participant_) throw std::runtime_error("cannot join ROS 2 domain " + std::to_string(domain) + " with Fast DDS");
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!publisher_ || !subscriber_) {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    throw std::runtime_error("cannot create a Fast DDS publisher and subscriber");
  }
}

FastDdsDomain::~FastDdsDomain() {
  if (!participant_) return;
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  participant_ = nullptr;
}

dds::Topic* FastDdsDomain::MakeTopic(const std::string& ros_topic, dds::TypeSupport type) {
  const std::string name = RosTopicToDds(ros_topic);
  if (dds::TopicDescription* existing = participant_->lookup_topicdescription(name))
    return static_cast<dds::Topic*>(existing);
  type->auto_fill_type_information(false);
  type->auto_fill_type_object(false);
  const std::string type_name = type.get_type_name();
  // Registering a type twice (two topics of one type) is refused; the first registration stands.
  const ReturnCode_t registered = type.register_type(participant_);
  if (registered != ReturnCode_t::RETCODE_OK && participant_->find_type(type_name).empty())
    throw std::runtime_error("cannot register the type " + type_name);
  dds::Topic* topic = participant_->create_topic(name, type_name, dds::TOPIC_QOS_DEFAULT);
  if (!topic) throw std::runtime_error("cannot create the topic " + name + " (" + type_name + ")");
  return topic;
}

dds::DataWriter* FastDdsDomain::Writer(dds::Topic* topic, const dds::DataWriterQos& qos) {
  dds::DataWriter* writer = publisher_->create_datawriter(topic, qos);
  if (!writer) throw std::runtime_error("cannot create the writer of " + topic->get_name());
  return writer;
}

dds::DataReader* FastDdsDomain::Reader(dds::Topic* topic, const dds::DataReaderQos& qos,
                                       dds::DataReaderListener* listener) {
  dds::DataReader* reader = subscriber_->create_datareader(topic, qos, listener);
  if (!reader) throw std::runtime_error("cannot create the reader of " + topic->get_name());
  return reader;
}

dds::DataWriterQos SensorWriterQos(bool reliable) {
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind = reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;  // Fast DDS's writer default is transient local
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = reliable ? 10 : 5;
  qos.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
  // Samples are as large as the frame: grow the preallocated buffers instead of sizing them from the
  // type's maximum (fastddsgen bounds an unbounded sequence at 100 elements there).
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return qos;
}

dds::DataReaderQos CountingReaderQos(bool reliable) {
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return qos;
}

dds::DataReaderQos TfStaticReaderQos() {
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 100;
  return qos;
}

}  // namespace fusecal::fastdds_peer
