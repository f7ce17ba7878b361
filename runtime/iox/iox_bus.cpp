#include "runtime/iox/iox_bus.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstring>
#include <ctime>
#include <exception>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "iceoryx_posh/mepoo/chunk_header.hpp"
#include "runtime/bus_url.hpp"
#include "runtime/channel_pattern.hpp"
#include "runtime/channels.hpp"
#include "runtime/deliver_to_handlers.hpp"
#include "runtime/iox/iceoryx_c.hpp"
#include "runtime/iox/iox_chunk.hpp"
#include "runtime/iox/iox_runtime.hpp"
#include "runtime/shared_memory.hpp"

namespace fusecal {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kDefaultDepth = 64;     // small channels: STATUS, motions, EXTRINSIC, ...
constexpr int kDefaultBulkDepth = 8;  // images, scans, stations: each queued one holds a pool chunk
// ParseBusUrl's ranges: depth= up to iceoryx 2.0's MAX_SUBSCRIBER_QUEUE_CAPACITY (256), max= short of
// 4 GiB by the chunk header.
static_assert(iox::kChunkHeaderBytes <= 64, "bus_url.hpp's max= range leaves 64 bytes for the header");
// Just under the 4 MiB chunks of RouDi's built-in pools (iceoryx's chunk header comes on top).
constexpr long kDefaultMax = 4 * 1024 * 1024 - static_cast<long>(shm::kChunkOverheadBytes);
constexpr auto kNewPublisherWait = std::chrono::milliseconds(250);  // > RouDi's 100 ms discovery loop
constexpr auto kDiscoveryInterval = std::chrono::milliseconds(100);
constexpr size_t kDiscoveryCapacity = 256;

std::atomic<uint64_t> g_bus_count{0};

// The payload bytes of a chunk a subscriber took (from iceoryx's chunk header).
size_t PayloadBytes(const void* payload) {
  const auto* header =
      reinterpret_cast<const ::iox::mepoo::ChunkHeader*>(iox_chunk_header_from_user_payload_const(payload));
  return header->userPayloadSize();
}

std::string AllocationError(iox_AllocationResult result) {
  switch (result) {
    case AllocationResult_RUNNING_OUT_OF_CHUNKS:
      return "RouDi's pool for this size has no free chunk (readers hold them all: raise bus.shm_chunks, or "
             "lower bulk_depth=)";
    case AllocationResult_NO_MEMPOOLS_AVAILABLE:
      return "RouDi has no pool for this size";
    case AllocationResult_TOO_MANY_CHUNKS_ALLOCATED_IN_PARALLEL:
      return "too many chunks loaned at once";
    default:
      return "iceoryx allocation error " + std::to_string(static_cast<int>(result));
  }
}

}  // namespace

struct IoxBus::Impl {
  struct Sub {
    ChannelPattern channel;
    RawHandler handler;
    bool active = true;
    bool Matches(const std::string& name) const { return channel.Matches(name); }
  };
  // iceoryx keeps pointers to its storage: each lives at a fixed address until deinit.
  struct Reader {
    std::string channel;
    iox_sub_storage_t storage{};
    iox_sub_t sub = nullptr;
    iox::SequenceGaps gaps;
    ~Reader() {
      if (sub) iox_sub_deinit(sub);
    }
  };
  struct Writer {
    iox_pub_storage_t storage{};
    iox_pub_t pub = nullptr;
    uint64_t sequence = 0;
    bool waited = false;  // for its first subscriber
    ~Writer() {
      if (pub) iox_pub_deinit(pub);
    }
  };

  std::string url;
  int depth = kDefaultDepth;
  int bulk_depth = kDefaultBulkDepth;
  long max_message = kDefaultMax;
  bool deliver_own = true;
  uint64_t origin = 0;

  // Readers are deleted after the waitset (members are destroyed in reverse order).
  std::map<std::string, std::unique_ptr<Reader>> readers;  // by channel
  iox_ws_storage_t waitset_storage{};
  iox_ws_t waitset = nullptr;
  iox_service_discovery_storage_t discovery_storage{};
  iox_service_discovery_t discovery = nullptr;
  Clock::time_point last_discovery{};

  std::mutex mutex;                                        // subs, readers, discovery
  std::mutex publish_mutex;                                // writers (a publisher is not thread-safe)
  std::map<std::string, std::unique_ptr<Writer>> writers;  // by channel
  std::vector<std::shared_ptr<Sub>> subs;
  std::atomic<uint64_t> dropped{0};
  std::exception_ptr pending_error;

  ~Impl() {
    writers.clear();
    if (waitset) iox_ws_deinit(waitset);  // detaches the readers
    readers.clear();
    if (discovery) iox_service_discovery_deinit(discovery);
  }

  // Reads depth=, bulk_depth=, max= and self= from the URL (checked by ParseBusUrl).
  void ParseUrl(const std::string& text) {
    const ParsedBusUrl parsed = ParseBusUrl(text);
    if (parsed.scheme != "iox") throw BusError("bus URL '" + text + "' is not an iox:// URL");
    depth = static_cast<int>(parsed.Get("depth", depth));
    bulk_depth = static_cast<int>(parsed.Get("bulk_depth", bulk_depth));
    max_message = parsed.Get("max", max_message);
    deliver_own = parsed.Get("self", deliver_own ? 1 : 0) == 1;
  }

  void EnsureReaderLocked(const std::string& channel) {
    if (readers.count(channel)) return;
    if (const std::string problem = iox::CheckChannelName(channel); !problem.empty())
      throw BusError("iceoryx subscribe on " + url + ": " + problem);
    iox::EnsureRuntime(url);
    auto reader = std::make_unique<Reader>();
    reader->channel = channel;
    iox_sub_options_t options;
    iox_sub_options_init(&options);
    // Channels of megabyte messages (runtime/channels.hpp) queue `bulk_depth`: each queued one holds a chunk.
    options.queueCapacity = static_cast<uint64_t>(TraitsOfChannel(channel).large ? bulk_depth : depth);
    options.historyRequest = 0;
    options.subscribeOnCreate = true;
    options.queueFullPolicy = QueueFullPolicy_DISCARD_OLDEST_DATA;
    options.requirePublisherHistorySupport = false;
    reader->sub = iox_sub_init(&reader->storage, iox::kService, channel.c_str(), iox::kEvent, &options);
    if (!reader->sub) throw BusError("iceoryx: cannot create a subscriber for channel " + channel + " on " + url);
    const auto attached = iox_ws_attach_subscriber_state(waitset, reader->sub, SubscriberState_HAS_DATA, 0, nullptr);
    if (attached != WaitSetResult_SUCCESS)
      throw BusError("iceoryx: cannot wait on channel " + channel + " on " + url +
                     (attached == WaitSetResult_WAIT_SET_FULL ? " (the waitset is full: too many channels)" : ""));
    readers[channel] = std::move(reader);
  }

  // A service of ours exists (a local or discovered publisher): read it if a pattern wants it.
  void OnChannelLocked(const std::string& channel) {
    if (readers.count(channel) || !iox::CheckChannelName(channel).empty()) return;
    for (const auto& sub : subs)
      if (sub->active && sub->Matches(channel)) return EnsureReaderLocked(channel);
  }

  bool HasPatternLocked() const {
    for (const auto& sub : subs)
      if (sub->active && !sub->channel.plain()) return true;
    return false;
  }

  // Subscribes the pattern subscriptions to the services offered since the last look.
  void DiscoverLocked() {
    last_discovery = Clock::now();
    if (!HasPatternLocked()) return;
    if (!discovery) discovery = iox_service_discovery_init(&discovery_storage);
    std::vector<iox_service_description_t> found(kDiscoveryCapacity);
    uint64_t missed = 0;
    const uint64_t n = iox_service_discovery_find_service(discovery, iox::kService, nullptr, iox::kEvent, found.data(),
                                                          found.size(), &missed, MessagingPattern_PUB_SUB);
    for (uint64_t i = 0; i < n && i < found.size(); ++i) {
      found[i].instanceString[sizeof found[i].instanceString - 1] = '\0';
      OnChannelLocked(found[i].instanceString);
    }
  }

  // A reader's next chunk, taken and not yet delivered (header null: none).
  struct Head {
    Reader* reader = nullptr;
    const void* payload = nullptr;
    const iox::IoxChunkHeader* header = nullptr;
  };
  // Takes the reader's next chunk of ours; after an error nothing more is taken.
  void TakeNext(Head& head) {
    for (;;) {
      head.payload = nullptr;
      head.header = nullptr;
      if (pending_error || iox_sub_take_chunk(head.reader->sub, &head.payload) != ChunkReceiveResult_SUCCESS) return;
      head.header = iox::ParseChunk(head.payload, PayloadBytes(head.payload));
      if (head.header) return;
      iox_sub_release_chunk(head.reader->sub, head.payload);
    }
  }

  // Takes every queued chunk and hands it, in place, to the matching handlers, merged across channels in
  // publish order (utime, then sequence): each channel has its own subscriber, and a stage that was busy
  // finds several waiting at once (a scan published before an image must reach the detector first, as
  // in the log). Returns the handler calls.
  int Drain() {
    std::vector<Head> heads;
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (auto& [channel, reader] : readers) heads.push_back(Head{reader.get()});
    }
    for (Head& head : heads) TakeNext(head);
    int delivered = 0;
    for (;;) {
      Head* first = nullptr;
      for (Head& head : heads)
        if (head.header && (!first || std::make_pair(head.header->utime, head.header->sequence) <
                                          std::make_pair(first->header->utime, first->header->sequence)))
          first = &head;
      if (!first) break;
      const iox::IoxChunkHeader& header = *first->header;
      dropped += first->reader->gaps.Count(header.origin, header.sequence);
      if (deliver_own || header.origin != origin) delivered += Deliver(*first->reader, header);
      iox_sub_release_chunk(first->reader->sub, first->payload);  // after every handler has returned
      TakeNext(*first);
    }
    return delivered;
  }

  int Deliver(const Reader& reader, const iox::IoxChunkHeader& header) {
    std::vector<std::shared_ptr<Sub>> matching;
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (const auto& sub : subs)
        if (sub->active && sub->Matches(reader.channel)) matching.push_back(sub);
    }
    const auto* bytes = reinterpret_cast<const uint8_t*>(&header) + iox::kChunkHeaderBytes;
    const RawMessage raw{reader.channel, bytes, static_cast<size_t>(header.size), NowUtime()};
    return DeliverToHandlers(matching, raw, pending_error);
  }

  Writer& WriterLocked(const std::string& channel) {
    auto it = writers.find(channel);
    if (it != writers.end()) return *it->second;
    if (const std::string problem = iox::CheckChannelName(channel); !problem.empty())
      throw BusError("iceoryx publish on " + url + ": " + problem);
    iox::EnsureRuntime(url);
    {
      // A pattern subscription of this bus must read the channel before the first message goes out.
      std::lock_guard<std::mutex> lock(mutex);
      OnChannelLocked(channel);
    }
    auto writer = std::make_unique<Writer>();
    iox_pub_options_t options;
    iox_pub_options_init(&options);
    options.historyCapacity = 0;  // volatile, as LCM
    options.offerOnCreate = true;
    options.subscriberTooSlowPolicy = ConsumerTooSlowPolicy_DISCARD_OLDEST_DATA;  // never block
    writer->pub = iox_pub_init(&writer->storage, iox::kService, channel.c_str(), iox::kEvent, &options);
    if (!writer->pub) throw BusError("iceoryx: cannot create a publisher for channel " + channel + " on " + url);
    return *writers.emplace(channel, std::move(writer)).first->second;
  }
};

IoxBus::IoxBus(const std::string& url) : impl_(std::make_shared<Impl>()) {
  Impl& d = *impl_;
  d.url = url;
  d.ParseUrl(url);
  iox::EnsureRuntime(url);
  d.origin = (static_cast<uint64_t>(getpid()) << 20) | (++g_bus_count & 0xfffff);
  d.waitset = iox_ws_init(&d.waitset_storage);
  if (!d.waitset) throw BusError("iceoryx: cannot create a waitset for " + url);
}

IoxBus::~IoxBus() = default;

std::string IoxBus::url() const { return impl_->url; }

uint64_t IoxBus::dropped_messages() const { return impl_->dropped.load(); }

void IoxBus::PublishRaw(const std::string& channel, const void* data, size_t size) {
  Impl& d = *impl_;
  if (static_cast<long double>(size) > static_cast<long double>(d.max_message))
    throw BusError("iceoryx: a " + std::to_string(size) + "-byte message on " + channel +
                   " is larger than RouDi's pools carry (max=" + std::to_string(d.max_message) + " bytes on " + d.url +
                   "; raise bus.max_message_mb, or the pools of the RouDi you started)");
  std::lock_guard<std::mutex> lock(d.publish_mutex);
  Impl::Writer& writer = d.WriterLocked(channel);  // (registers with RouDi first)
  // max= may be larger than the pools of the RouDi that runs (one started by hand): iceoryx would abort.
  if (const size_t largest = iox::LargestChunkPayload(); largest > 0 && iox::kChunkHeaderBytes + size > largest)
    throw BusError("iceoryx: a " + std::to_string(size) + "-byte message on " + channel +
                   " is larger than the largest chunk of the running RouDi's pools (" + std::to_string(largest) +
                   " bytes with a " + std::to_string(iox::kChunkHeaderBytes) + "-byte header, " + d.url +
                   "): start RouDi with larger pools (`fusecal run` plans them from bus.max_message_mb)");
  if (!writer.waited) {
    // RouDi connects a new publisher to the existing subscribers in its discovery loop (every 100 ms);
    // a message published before that is lost to them.
    writer.waited = true;
    const auto until = Clock::now() + kNewPublisherWait;
    while (!iox_pub_has_subscribers(writer.pub) && Clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  void* chunk = nullptr;
  const uint32_t chunk_bytes = static_cast<uint32_t>(iox::kChunkHeaderBytes + size);
  const iox_AllocationResult result = iox_pub_loan_chunk(writer.pub, &chunk, chunk_bytes);
  if (result != AllocationResult_SUCCESS)
    throw BusError("iceoryx: cannot publish a " + std::to_string(size) + "-byte message on " + channel + " over " +
                   d.url + ": " + AllocationError(result));
  iox::IoxChunkHeader header;
  header.magic = iox::kChunkMagic;
  header.origin = d.origin;
  header.sequence = ++writer.sequence;
  header.utime = NowUtime();
  header.size = size;
  std::memcpy(chunk, &header, sizeof header);
  if (size > 0) std::memcpy(static_cast<uint8_t*>(chunk) + iox::kChunkHeaderBytes, data, size);  // the one copy
  iox_pub_publish_chunk(writer.pub, chunk);
}

Subscription IoxBus::SubscribeRaw(const std::string& channel, RawHandler handler) {
  Impl& d = *impl_;
  auto sub = std::make_shared<Impl::Sub>(Impl::Sub{ChannelPattern(channel, "iceoryx subscribe"), std::move(handler)});
  std::vector<std::string> published;  // this bus's own channels (a pattern may want them)
  if (!sub->channel.plain()) {
    std::lock_guard<std::mutex> lock(d.publish_mutex);  // (taken before `mutex`, as in PublishRaw)
    for (const auto& [name, writer] : d.writers) published.push_back(name);
  }
  {
    std::lock_guard<std::mutex> lock(d.mutex);
    if (sub->channel.plain()) d.EnsureReaderLocked(channel);  // (throws before the sub is registered)
    d.subs.push_back(sub);
    if (!sub->channel.plain()) {
      for (const auto& name : published) d.OnChannelLocked(name);
      d.DiscoverLocked();
    }
  }
  std::weak_ptr<Impl> weak = impl_;
  return Subscription([weak, sub]() {
    sub->active = false;
    auto impl = weak.lock();
    if (!impl) return;
    std::lock_guard<std::mutex> lock(impl->mutex);
    impl->subs.erase(std::remove(impl->subs.begin(), impl->subs.end(), sub), impl->subs.end());
  });
}

int IoxBus::Handle(int timeout_ms) {
  Impl& d = *impl_;
  const auto deadline = Clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  int delivered = 0;
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(d.mutex);
      if (Clock::now() - d.last_discovery >= kDiscoveryInterval) d.DiscoverLocked();
    }
    delivered += d.Drain();
    if (d.pending_error) {
      std::exception_ptr error = d.pending_error;
      d.pending_error = nullptr;
      std::rethrow_exception(error);
    }
    const auto now = Clock::now();
    if (delivered > 0 || now >= deadline) return delivered;
    // Wake at the deadline, or sooner to look for new services of the pattern subscriptions.
    auto wait = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - now);
    wait = std::min<std::chrono::nanoseconds>(wait, kDiscoveryInterval);
    timespec timeout{static_cast<time_t>(wait.count() / 1000000000), static_cast<long>(wait.count() % 1000000000)};
    iox_notification_info_t notifications[16];
    uint64_t missed = 0;
    iox_ws_timed_wait(d.waitset, timeout, notifications, 16, &missed);
  }
}

}  // namespace fusecal
