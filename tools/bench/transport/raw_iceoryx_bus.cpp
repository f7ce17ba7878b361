#include "tools/bench/transport/raw_iceoryx_bus.hpp"

#include <chrono>
#include <cstring>
#include <ctime>
#include <exception>
#include <map>
#include <vector>

#include "iceoryx_posh/mepoo/chunk_header.hpp"
#include "runtime/bus_url.hpp"
#include "runtime/iox/iceoryx_c.hpp"
#include "runtime/iox/iox_runtime.hpp"

namespace fusecal::bench {

namespace {

constexpr const char* kService = "fusecal_bench";
constexpr const char* kEvent = "raw";

class RawIceoryxBus : public Bus {
 public:
  explicit RawIceoryxBus(const std::string& url) : url_(url) {
    const std::string depth = UrlParameter(url, "depth");
    depth_ = depth.empty() ? 8 : std::stoi(depth);
    iox::EnsureRuntime(url);
    waitset_ = iox_ws_init(&waitset_storage_);
  }
  ~RawIceoryxBus() override {
    for (auto& [channel, pub] : pubs_) iox_pub_deinit(pub->handle);
    iox_ws_deinit(waitset_);
    for (auto& sub : subs_) iox_sub_deinit(sub->handle);
  }

  std::string url() const override { return url_; }

  void PublishRaw(const std::string& channel, const void* data, size_t size) override {
    auto& pub = pubs_[channel];
    if (!pub) {
      pub = std::make_unique<Pub>();
      iox_pub_options_t options;
      iox_pub_options_init(&options);
      options.subscriberTooSlowPolicy = ConsumerTooSlowPolicy_DISCARD_OLDEST_DATA;
      pub->handle = iox_pub_init(&pub->storage, kService, channel.c_str(), kEvent, &options);
    }
    void* chunk = nullptr;
    if (iox_pub_loan_chunk(pub->handle, &chunk, static_cast<uint32_t>(size)) != AllocationResult_SUCCESS)
      throw BusError("iceoryx-raw: no chunk for a " + std::to_string(size) + "-byte message");
    std::memcpy(chunk, data, size);
    iox_pub_publish_chunk(pub->handle, chunk);
  }

  Subscription SubscribeRaw(const std::string& channel, RawHandler handler) override {
    auto sub = std::make_unique<Sub>();
    sub->channel = channel;
    sub->handler = std::move(handler);
    iox_sub_options_t options;
    iox_sub_options_init(&options);
    options.queueCapacity = static_cast<uint64_t>(depth_);
    options.queueFullPolicy = QueueFullPolicy_DISCARD_OLDEST_DATA;
    sub->handle = iox_sub_init(&sub->storage, kService, channel.c_str(), kEvent, &options);
    iox_ws_attach_subscriber_state(waitset_, sub->handle, SubscriberState_HAS_DATA, 0, nullptr);
    subs_.push_back(std::move(sub));
    return Subscription();  // the probes never unsubscribe
  }

  int Handle(int timeout_ms) override {
    int delivered = Drain();
    if (delivered > 0 || timeout_ms <= 0) return delivered;
    const timespec timeout{timeout_ms / 1000, (timeout_ms % 1000) * 1000000L};
    iox_notification_info_t notifications[8];
    uint64_t missed = 0;
    iox_ws_timed_wait(waitset_, timeout, notifications, 8, &missed);
    return Drain();
  }

 private:
  struct Pub {
    iox_pub_storage_t storage{};
    iox_pub_t handle = nullptr;
  };
  struct Sub {
    std::string channel;
    RawHandler handler;
    iox_sub_storage_t storage{};
    iox_sub_t handle = nullptr;
  };

  int Drain() {
    int delivered = 0;
    std::exception_ptr error;
    for (auto& sub : subs_) {
      const void* payload = nullptr;
      while (iox_sub_take_chunk(sub->handle, &payload) == ChunkReceiveResult_SUCCESS) {
        const auto* header =
            reinterpret_cast<const ::iox::mepoo::ChunkHeader*>(iox_chunk_header_from_user_payload_const(payload));
        try {
          sub->handler(
              RawMessage{sub->channel, static_cast<const uint8_t*>(payload), header->userPayloadSize(), NowUtime()});
        } catch (...) {
          if (!error) error = std::current_exception();
        }
        iox_sub_release_chunk(sub->handle, payload);
        ++delivered;
      }
    }
    if (error) std::rethrow_exception(error);
    return delivered;
  }

  std::string url_;
  int depth_ = 8;
  iox_ws_storage_t waitset_storage_{};
  iox_ws_t waitset_ = nullptr;
  std::map<std::string, std::unique_ptr<Pub>> pubs_;
  std::vector<std::unique_ptr<Sub>> subs_;
};

}  // namespace

bool IsRawIceoryxUrl(const std::string& url) { return url.rfind("iceoryx-raw://", 0) == 0; }

std::unique_ptr<Bus> MakeRawIceoryxBus(const std::string& url) { return std::make_unique<RawIceoryxBus>(url); }

}  // namespace fusecal::bench
