// Joining a ROS 2 domain on Fast DDS as rmw_fastrtps does: Fast DDS's transports (UDPv4 and shared
// memory, on every interface; only their buffers are larger, for multi-MB samples), ROS 2 topic and type
// names, and types registered without XTypes type information (rmw_fastrtps sets
// auto_fill_type_information(false); Cyclone DDS would otherwise discard the type information Fast DDS
// 2.x sends, and with it the match).
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>

namespace fusecal::fastdds_peer {

namespace dds = eprosima::fastdds::dds;

// A participant with one publisher and one subscriber; the destructor deletes all it created. Throws
// std::runtime_error when an entity cannot be created.
class FastDdsDomain {
 public:
  explicit FastDdsDomain(int domain);
  ~FastDdsDomain();
  FastDdsDomain(const FastDdsDomain&) = delete;
  FastDdsDomain& operator=(const FastDdsDomain&) = delete;

  // The DDS topic of `ros_topic` (/camera/image_raw -> rt/camera/image_raw) with the type of `PubSubType`
  // (a fastddsgen TopicDataType), created once.
  template <typename PubSubType>
  dds::Topic* Topic(const std::string& ros_topic) {
    return MakeTopic(ros_topic, dds::TypeSupport(new PubSubType()));
  }
  dds::DataWriter* Writer(dds::Topic* topic, const dds::DataWriterQos& qos);
  dds::DataReader* Reader(dds::Topic* topic, const dds::DataReaderQos& qos, dds::DataReaderListener* listener);

 private:
  dds::Topic* MakeTopic(const std::string& ros_topic, dds::TypeSupport type);

  dds::DomainParticipant* participant_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
};

// A sensor driver's writer: reliable (ROS 2's default profile, keep last 10) or best effort (the sensor
// data profile, keep last 5); volatile; synchronous publication, rmw_fastrtps' default.
dds::DataWriterQos SensorWriterQos(bool reliable);

// A reader that counts everything it is sent: keep all, so that no sample is replaced before it is taken.
dds::DataReaderQos CountingReaderQos(bool reliable);

// tf2_ros's static transform listener: reliable, transient local (a late joiner gets the latest
// transforms), keep last 100.
dds::DataReaderQos TfStaticReaderQos();

}  // namespace fusecal::fastdds_peer
