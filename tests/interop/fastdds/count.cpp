// `count`: a Fast DDS subscriber of sensor topics that counts what arrives (self-tests, benchmarks).
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "fastdds_domain.hpp"
#include "fastdds_generated/ros2_messagesPubSubTypes.h"
#include "peer_commands.hpp"

namespace fusecal::fastdds_peer {
namespace {

using Clock = std::chrono::steady_clock;

// What arrived on one topic; the counts are written on Fast DDS's thread and read on the main one.
class Counter : public dds::DataReaderListener {
 public:
  explicit Counter(std::string topic) : topic_(std::move(topic)) {}
  const std::string& topic() const { return topic_; }
  void Snapshot(long* messages, uint64_t* bytes, Clock::time_point* last) const {
    std::lock_guard<std::mutex> lock(mutex_);
    *messages = messages_, *bytes = bytes_, *last = last_;
  }

 protected:
  void Add(uint64_t bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++messages_, bytes_ += bytes, last_ = Clock::now();
  }

 private:
  std::string topic_;
  mutable std::mutex mutex_;
  long messages_ = 0;
  uint64_t bytes_ = 0;
  Clock::time_point last_{};
};

template <typename Message>
class TypedCounter : public Counter {
 public:
  using Counter::Counter;
  void on_data_available(dds::DataReader* reader) override {
    Message sample;
    dds::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      if (info.valid_data) Add(Message::getCdrSerializedSize(sample));  // the sample's CDR size
  }
};

// "/name:Type", or "/name" with the type its name suggests.
std::string TypeOf(const std::string& spec, std::string* topic) {
  const size_t colon = spec.find(':');
  *topic = spec.substr(0, colon);
  if (colon != std::string::npos) return spec.substr(colon + 1);
  auto ends_with = [&](const std::string& tail) {
    return topic->size() >= tail.size() && topic->compare(topic->size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends_with("/compressed")) return "CompressedImage";
  if (ends_with("camera_info")) return "CameraInfo";
  if (topic->find("points") != std::string::npos || topic->find("cloud") != std::string::npos) return "PointCloud2";
  return "Image";
}

template <typename PubSubType>
std::unique_ptr<Counter> Subscribe(FastDdsDomain& domain, const std::string& topic, bool best_effort) {
  auto counter = std::make_unique<TypedCounter<typename PubSubType::type>>(topic);
  domain.Reader(domain.Topic<PubSubType>(topic), CountingReaderQos(!best_effort), counter.get());
  return counter;
}

std::unique_ptr<Counter> Subscribe(FastDdsDomain& domain, const std::string& spec, bool best_effort) {
  std::string topic;
  const std::string type = TypeOf(spec, &topic);
  namespace msg = sensor_msgs::msg::dds_;
  if (type == "Image") return Subscribe<msg::Image_PubSubType>(domain, topic, best_effort);
  if (type == "CompressedImage") return Subscribe<msg::CompressedImage_PubSubType>(domain, topic, best_effort);
  if (type == "PointCloud2") return Subscribe<msg::PointCloud2_PubSubType>(domain, topic, best_effort);
  if (type == "CameraInfo") return Subscribe<msg::CameraInfo_PubSubType>(domain, topic, best_effort);
  throw std::runtime_error("unknown type '" + type + "' of " + topic +
                           " (Image, CompressedImage, PointCloud2 or CameraInfo)");
}

}  // namespace

int Count(int domain_id, double seconds, double idle_s, bool best_effort, const std::vector<std::string>& topics) {
  // The counters outlive the domain: its readers call them until they are deleted.
  std::vector<std::unique_ptr<Counter>> counters;
  FastDdsDomain domain(domain_id);
  for (const std::string& spec : topics) counters.push_back(Subscribe(domain, spec, best_effort));
  const auto start = Clock::now();
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto now = Clock::now();
    if (now - start >= std::chrono::duration<double>(seconds)) break;
    Clock::time_point last{};
    for (const auto& c : counters) {
      long n;
      uint64_t b;
      Clock::time_point t;
      c->Snapshot(&n, &b, &t);
      last = std::max(last, t);
    }
    if (idle_s > 0 && last != Clock::time_point{} && now - last >= std::chrono::duration<double>(idle_s)) break;
  }
  std::string text = "{\"received\": {";
  for (size_t i = 0; i < counters.size(); ++i) {
    long n;
    uint64_t b;
    Clock::time_point t;
    counters[i]->Snapshot(&n, &b, &t);
    text += (i ? ", \"" : "\"") + counters[i]->topic() + "\": {\"messages\": " + std::to_string(n) +
            ", \"bytes\": " + std::to_string(b) + "}";
  }
  std::printf("%s}, \"seconds\": %.3f}\n", text.c_str(), std::chrono::duration<double>(Clock::now() - start).count());
  return 0;
}

}  // namespace fusecal::fastdds_peer
