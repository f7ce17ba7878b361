#include "runtime/dds/dds_bus.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "dds/dds.h"
#include "fusecal_bytes.h"
#include "runtime/bus_url.hpp"
#include "runtime/channel_pattern.hpp"
#include "runtime/channels.hpp"
#include "runtime/dds/dds_envelope.hpp"
#include "runtime/deliver_to_handlers.hpp"
#include "runtime/shared_memory.hpp"

namespace fusecal {

namespace {

constexpr const char* kTypeName = "fusecal::lcm_message";
constexpr int kDefaultDepth = 64;     // small channels: STATUS, motions, EXTRINSIC, ...
constexpr int kDefaultBulkDepth = 8;  // images, scans, stations
constexpr int kTakeBatch = 64;
constexpr int kBulkTakeBatch = 4;
constexpr int kNewWriterWaitMs = 250;  // > RouDi's discovery interval (100 ms in iceoryx 2.0)
// iceoryx aborts the process when a sample needs a chunk larger than RouDi's largest mempool (4 MiB in
// RouDi's built-in configuration). Larger messages go through a writer with a deadline, which Cyclone
// never puts on shared memory, i.e. over the network path. shm_max= raises this for a RouDi configured
// with larger chunks (`fusecal run` sets it from the pools it gives RouDi).
constexpr long kDefaultShmMax = 4 * 1024 * 1024 - static_cast<long>(shm::kChunkOverheadBytes);

int64_t WallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string DdsError(dds_return_t rc) { return dds_strretcode(rc < 0 ? -rc : rc); }

// Cyclone configuration sized for 2-6 MB samples: 64 KB datagrams in ~62 KB fragments (a 6 MB image is
// ~100 datagrams, not 4600 of 1344 B), a receive buffer as large as the kernel allows (up to 64 MB,
// `fusecal doctor` raises net.core.rmem_max), and a writer history cache that holds a few images.
std::string CycloneConfig(bool shm) {
  std::string xml =
      "<CycloneDDS><Domain id=\"any\">"
      "<General><MaxMessageSize>65500B</MaxMessageSize>"
      "<MaxRexmitMessageSize>65500B</MaxRexmitMessageSize>"
      "<FragmentSize>62000B</FragmentSize></General>"
      "<Internal><SocketReceiveBufferSize min=\"default\" max=\"64MiB\"/>"
      "<SocketSendBufferSize min=\"default\" max=\"4MiB\"/>"
      "<Watermarks><WhcHigh>64MiB</WhcHigh></Watermarks></Internal>";
  if (shm) xml += "<SharedMemory><Enable>true</Enable><LogLevel>warn</LogLevel></SharedMemory>";
  xml += "</Domain></CycloneDDS>";
  // A user configuration ($CYCLONEDDS_URI: file URIs or XML) is applied on top of ours.
  if (const char* env = std::getenv("CYCLONEDDS_URI"); env && *env) xml += std::string(",") + env;
  return xml;
}

// Domains this process created with our configuration, shared by every DdsBus on that domain id and
// deleted with the last one.
struct DomainEntry {
  dds_entity_t domain = 0;
  int users = 0;
  bool shm = false;
};
std::mutex g_domains_mutex;
std::map<uint32_t, DomainEntry> g_domains;

}  // namespace

struct DdsBus::Impl {
  struct Sub {
    ChannelPattern channel;
    RawHandler handler;
    bool active = true;
    bool Matches(const std::string& name) const { return channel.Matches(name); }
  };
  // Samples are taken into memory kept from one take to the next: a 6 MB message is copied into the
  // buffer of an earlier one instead of a fresh allocation (and its page faults) per message. Bulk
  // channels take a few at a time so that the kept buffers stay small.
  struct Reader {
    std::string channel;
    dds_entity_t reader = 0;
    dds_entity_t condition = 0;
    std::vector<fusecal_lcm_message> samples;  // zero-initialised; contents owned here
    ~Reader() {
      for (auto& sample : samples) dds_sample_free(&sample, &fusecal_lcm_message_desc, DDS_FREE_CONTENTS);
    }
  };

  std::string url;
  uint32_t domain_id = 0;
  int depth = kDefaultDepth;
  int bulk_depth = kDefaultBulkDepth;
  bool shm_requested = false;
  long shm_max = kDefaultShmMax;
  bool shm = false;
  bool owns_domain_ref = false;

  dds_entity_t participant = 0;
  dds_entity_t waitset = 0;
  dds_entity_t publications = 0;  // DCPSPublication reader (for regex subscriptions)
  dds_entity_t publications_condition = 0;
  std::map<std::pair<std::string, bool>, dds_qos_t*> qos_by_channel;  // by channel and oversized (QosFor)

  std::mutex mutex;
  std::map<std::string, dds_entity_t> topics;         // by channel
  std::map<std::string, dds_entity_t> writers;        // by channel
  std::map<std::string, dds_entity_t> large_writers;  // by channel, for samples over shm_max (shm only)
  std::map<dds_entity_t, uint64_t> sent;              // by writer: the last sequence number written
  std::set<std::string> large_notice_given;           // channels whose large samples were announced
  dds::SequenceGaps gaps;                             // by remote writer: the sequence numbers read
  std::atomic<uint64_t> dropped{0};
  std::map<std::string, std::shared_ptr<Reader>> readers;  // by channel
  std::vector<std::shared_ptr<Sub>> subs;
  std::exception_ptr pending_error;

  ~Impl() {
    if (participant > 0) dds_delete(participant);  // deletes every child entity
    for (auto& [key, qos] : qos_by_channel) dds_delete_qos(qos);
    if (owns_domain_ref) {
      std::lock_guard<std::mutex> lock(g_domains_mutex);
      auto it = g_domains.find(domain_id);
      if (it != g_domains.end() && --it->second.users == 0) {
        dds_delete(it->second.domain);
        g_domains.erase(it);
      }
    }
  }

  // The QoS of a channel by its traits (runtime/channels.hpp), built once. Every participant builds the
  // same one for a channel, so that all its writers and readers match.
  //   state, small:  reliable, keep last `depth` (a round of the alternation is a few samples)
  //   state, large (STATION): reliable, keep all: a reader that falls behind holds its writer back instead
  //                  of losing a station; on shared memory keep last `bulk_depth` (Cyclone puts only
  //                  keep-last endpoints on iceoryx, and every held sample is a pool chunk)
  //   bulk (raw frames): best effort, keep last `bulk_depth`: a reader that falls behind, or one behind a
  //                  lossy link (a recorder on another host), never holds the writer back; a reliable
  //                  writer blocks up to 1 s on a full history and then drops the frame for every reader
  //                  (measured: with 5 % loss towards a remote recorder the local detector lost frames)
  //   oversized (shm only: larger than a chunk): the same plus a deadline, which Cyclone 0.10 never puts
  //                  on shared memory, so such samples take the network path; compatible with every reader
  //                  (they request none).
  // Volatile: a reader gets what is written after it matched. Transient-local would hand a reader that
  // joins late (a restarted stage) the writer's last sample ahead of the stations it is given again, out
  // of order (measured: ICP then paired station 1 with 0). The first sample of a new writer is protected
  // by the wait in PublishRaw instead.
  const dds_qos_t* QosFor(const std::string& channel, bool oversized = false) {
    auto& qos = qos_by_channel[{channel, oversized}];
    if (qos) return qos;
    const ChannelTraits traits = TraitsOfChannel(channel);
    qos = dds_create_qos();
    if (traits.kind == ChannelKind::kBulk)
      dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
    else
      dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    if (traits.kind == ChannelKind::kBulk || (traits.large && shm))
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, bulk_depth);
    else if (traits.large)
      dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    else
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
    if (oversized) dds_qset_deadline(qos, DDS_SECS(24 * 3600));
    return qos;
  }

  dds_entity_t TopicLocked(const std::string& channel) {
    auto it = topics.find(channel);
    if (it != topics.end()) return it->second;
    const std::string name = dds::TopicName(channel);
    const dds_entity_t topic = dds_create_topic(participant, &fusecal_lcm_message_desc, name.c_str(), nullptr, nullptr);
    if (topic < 0)
      throw BusError("DDS: cannot create topic '" + name + "' for channel " + channel + " on " + url + ": " +
                     DdsError(topic));
    topics[channel] = topic;
    return topic;
  }

  void EnsureReaderLocked(const std::string& channel) {
    if (readers.count(channel)) return;
    auto reader = std::make_shared<Reader>();
    reader->channel = channel;
    reader->samples.resize(TraitsOfChannel(channel).large ? kBulkTakeBatch : kTakeBatch);
    reader->reader = dds_create_reader(participant, TopicLocked(channel), QosFor(channel), nullptr);
    if (reader->reader < 0)
      throw BusError("DDS: cannot create a reader for channel " + channel + " on " + url + ": " +
                     DdsError(reader->reader));
    reader->condition = dds_create_readcondition(reader->reader, DDS_ANY_STATE);
    if (reader->condition < 0 || dds_waitset_attach(waitset, reader->condition, 0) < 0)
      throw BusError("DDS: cannot wait on the reader for channel " + channel + " on " + url);
    readers[channel] = std::move(reader);
  }

  // A topic of our type exists (a local or discovered writer): read it if a pattern wants it.
  void OnTopicLocked(const std::string& channel) {
    if (readers.count(channel)) return;
    for (const auto& sub : subs)
      if (sub->active && sub->Matches(channel)) return EnsureReaderLocked(channel);
  }

  void EnsurePublicationsReaderLocked() {
    if (publications > 0) return;
    dds_qos_t* builtin_qos = dds_create_qos();
    dds_qset_history(builtin_qos, DDS_HISTORY_KEEP_ALL, 0);
    publications = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, builtin_qos, nullptr);
    dds_delete_qos(builtin_qos);
    if (publications < 0) throw BusError("DDS: cannot read DCPSPublication on " + url + ": " + DdsError(publications));
    publications_condition = dds_create_readcondition(publications, DDS_ANY_STATE);
    if (publications_condition < 0 || dds_waitset_attach(waitset, publications_condition, 0) < 0)
      throw BusError("DDS: cannot wait on DCPSPublication on " + url);
  }

  // Creates readers for the topics of writers seen since the last call. Returns whether any was read.
  bool ScanPublicationsLocked() {
    if (publications <= 0) return false;
    void* samples[kTakeBatch] = {nullptr};
    dds_sample_info_t infos[kTakeBatch];
    bool any = false;
    for (;;) {
      const int n = dds_take(publications, samples, infos, kTakeBatch, kTakeBatch);
      if (n <= 0) break;
      any = true;
      std::vector<std::string> channels;
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* endpoint = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
        if (endpoint->type_name && endpoint->topic_name && std::strcmp(endpoint->type_name, kTypeName) == 0)
          channels.push_back(dds::ChannelName(endpoint->topic_name));
      }
      dds_return_loan(publications, samples, n);
      for (const auto& channel : channels) OnTopicLocked(channel);
      if (n < kTakeBatch) break;
    }
    return any;
  }

  // What one reader has taken and not yet delivered.
  struct Taken {
    std::shared_ptr<Reader> reader;
    std::vector<std::shared_ptr<Sub>> matching;
    std::vector<dds_sample_info_t> infos;
    int count = 0, next = 0;
    bool full = false;  // the take filled the batch: the reader may hold more
    const fusecal_lcm_message& Next() const { return reader->samples[static_cast<size_t>(next)]; }
  };

  // Takes the next batch of `t.reader` into its kept samples, and the subscriptions that match it.
  void TakeBatch(Taken& t) {
    const int batch = static_cast<int>(t.reader->samples.size());
    void* samples[kTakeBatch];
    for (int i = 0; i < batch; ++i) samples[i] = &t.reader->samples[static_cast<size_t>(i)];
    t.infos.resize(static_cast<size_t>(batch));
    const int n =
        dds_take(t.reader->reader, samples, t.infos.data(), static_cast<size_t>(batch), static_cast<uint32_t>(batch));
    t.count = std::max(n, 0);
    t.next = 0;
    t.full = n == batch;
    std::lock_guard<std::mutex> lock(mutex);
    t.matching.clear();
    for (const auto& sub : subs)
      if (sub->active && sub->Matches(t.reader->channel)) t.matching.push_back(sub);
  }

  // Delivers what every reader holds, merged in publish order (the writers' utime, then their sequence
  // number): each channel is its own topic and reader, and a stage that was busy finds several channels
  // waiting at once; taken reader by reader, a scan published before an image would reach the
  // stationarity detector after it, and a run would not compute what `calibrate` does in log order.
  // Returns the handler calls.
  int Drain() {
    std::vector<Taken> taken;
    {
      std::lock_guard<std::mutex> lock(mutex);
      ScanPublicationsLocked();
      for (auto& [channel, reader] : readers) taken.push_back(Taken{reader, {}, {}, 0, 0, false});
    }
    for (Taken& t : taken) TakeBatch(t);
    int delivered = 0;
    for (;;) {
      Taken* first = nullptr;
      for (Taken& t : taken) {
        // After an error, what was taken is still delivered, and nothing more is taken.
        if (t.next == t.count && t.full && !pending_error) TakeBatch(t);
        if (t.next == t.count) continue;
        if (!first || std::make_pair(t.Next().utime, t.Next().seq_number) <
                          std::make_pair(first->Next().utime, first->Next().seq_number))
          first = &t;
      }
      if (!first) break;
      const int i = first->next++;
      if (!first->infos[static_cast<size_t>(i)].valid_data) continue;
      const fusecal_lcm_message& message = first->reader->samples[static_cast<size_t>(i)];
      dropped += gaps.Count(first->infos[static_cast<size_t>(i)].publication_handle, message.seq_number);
      const int64_t receive_utime = WallUtime();  // when this bus took it (LCM: when it was read)
      const RawMessage raw{first->reader->channel, message.data._buffer, message.data._length, receive_utime};
      delivered += DeliverToHandlers(first->matching, raw, pending_error);
    }
    return delivered;
  }

  // Reads domain=, shm=, depth=, bulk_depth= and shm_max= from the URL (checked by ParseBusUrl).
  void ParseUrl(const std::string& text) {
    const ParsedBusUrl parsed = ParseBusUrl(text);
    if (parsed.scheme != "dds") throw BusError("bus URL '" + text + "' is not a dds:// URL");
    domain_id = static_cast<uint32_t>(parsed.Get("domain", domain_id));
    shm_requested = parsed.Get("shm", shm_requested ? 1 : 0) == 1;
    depth = static_cast<int>(parsed.Get("depth", depth));
    bulk_depth = static_cast<int>(parsed.Get("bulk_depth", bulk_depth));
    shm_max = parsed.Get("shm_max", shm_max);
  }

  // Shared memory only when asked for and a RouDi runs; otherwise the network path, said once.
  void ChooseSharedMemory() {
    shm = shm_requested;
    if (shm && !shm::RoudiRunning()) {
      std::fprintf(stderr,
                   "fusecal: %s: shm=1 but no iceoryx RouDi is running (start iox-roudi); using the "
                   "network path instead of shared memory\n",
                   url.c_str());
      shm = false;
    }
  }

  // Creates the domain (one per process and domain id, shared by the buses on it).
  void OpenDomain() {
    {
      std::lock_guard<std::mutex> lock(g_domains_mutex);
      auto it = g_domains.find(domain_id);
      if (it == g_domains.end()) {
        const std::string config = CycloneConfig(shm);
        const dds_entity_t domain = dds_create_domain(domain_id, config.c_str());
        if (domain > 0) {
          it = g_domains.emplace(domain_id, DomainEntry{domain, 0, shm}).first;
        } else if (domain != DDS_RETCODE_PRECONDITION_NOT_MET) {  // not: created outside DdsBus
          throw BusError("DDS: cannot create domain " + std::to_string(domain_id) + " for " + url + ": " +
                         DdsError(domain));
        }
      }
      if (it != g_domains.end()) {
        ++it->second.users;
        owns_domain_ref = true;
        if (it->second.shm != shm) {
          std::fprintf(stderr, "fusecal: %s: DDS domain %u is already open in this process with shm=%d; using that\n",
                       url.c_str(), domain_id, it->second.shm ? 1 : 0);
          shm = it->second.shm;
        }
      }
    }
  }

  // The participant and the waitset that Handle() waits on.
  void CreateParticipant() {
    participant = dds_create_participant(domain_id, nullptr, nullptr);
    if (participant < 0)
      throw BusError("DDS: cannot create a participant on domain " + std::to_string(domain_id) + " for " + url + ": " +
                     DdsError(participant));
    waitset = dds_create_waitset(participant);
    if (waitset < 0) throw BusError("DDS: cannot create a waitset for " + url);
  }
};

DdsBus::DdsBus(const std::string& url) : impl_(std::make_shared<Impl>()) {
  Impl& d = *impl_;
  d.url = url;
  d.ParseUrl(url);
  d.ChooseSharedMemory();
  d.OpenDomain();
  d.CreateParticipant();
}

DdsBus::~DdsBus() = default;

std::string DdsBus::url() const { return impl_->url; }

bool DdsBus::shared_memory() const { return impl_->shm; }

uint64_t DdsBus::dropped_messages() const { return impl_->dropped.load(); }

void DdsBus::PublishRaw(const std::string& channel, const void* data, size_t size) {
  Impl& d = *impl_;
  if (size > 0xffffffffu) throw BusError("DDS: message on channel " + channel + " is too large");
  dds_entity_t writer;
  bool new_writer = false;
  uint64_t seq_number = 0;
  {
    std::lock_guard<std::mutex> lock(d.mutex);
    const bool large = d.shm && static_cast<long>(size) > d.shm_max;
    if (large && d.large_notice_given.insert(channel).second)
      std::fprintf(stderr,
                   "fusecal: %s: a %zu-byte message on %s is larger than the biggest shared-memory chunk "
                   "carries (shm_max=%ld); such messages go over the network path (raise bus.max_message_mb "
                   "so that RouDi's pools hold them)\n",
                   d.url.c_str(), size, channel.c_str(), d.shm_max);
    auto& writers = large ? d.large_writers : d.writers;
    auto it = writers.find(channel);
    if (it == writers.end()) {
      // A pattern subscription of this bus must read the channel before the first sample is written.
      d.OnTopicLocked(channel);
      writer = dds_create_writer(d.participant, d.TopicLocked(channel), d.QosFor(channel, large), nullptr);
      if (writer < 0)
        throw BusError("DDS: cannot create a writer for channel " + channel + " on " + d.url + ": " + DdsError(writer));
      writers[channel] = writer;
      new_writer = true;
    } else {
      writer = it->second;
    }
    seq_number = ++d.sent[writer];
  }
  // A new writer reaches the readers that exist only once they know of it: over the network path when
  // its discovery message has arrived, over shared memory when RouDi's discovery loop (every 100 ms) has
  // connected the iceoryx ports. A sample written before that is lost to them. Measured: without this
  // wait the first LIDAR_MOTION of a run over shared memory never reached the hand-eye stage.
  if (new_writer) std::this_thread::sleep_for(std::chrono::milliseconds(kNewWriterWaitMs));
  fusecal_lcm_message message{};
  message.channel = const_cast<char*>(channel.c_str());
  message.utime = WallUtime();
  message.seq_number = seq_number;
  message.data._maximum = message.data._length = static_cast<uint32_t>(size);
  message.data._buffer = static_cast<uint8_t*>(const_cast<void*>(data));
  message.data._release = false;
  const dds_return_t rc = dds_write(writer, &message);
  if (rc < 0)
    throw BusError("DDS publish failed on channel " + channel + " (" + std::to_string(size) + " bytes) over " + d.url +
                   ": " + DdsError(rc));
}

Subscription DdsBus::SubscribeRaw(const std::string& channel, RawHandler handler) {
  Impl& d = *impl_;
  auto sub = std::make_shared<Impl::Sub>(Impl::Sub{ChannelPattern(channel, "DDS subscribe"), std::move(handler)});
  {
    std::lock_guard<std::mutex> lock(d.mutex);
    d.subs.push_back(sub);
    if (sub->channel.plain()) {
      d.EnsureReaderLocked(channel);
    } else {
      d.EnsurePublicationsReaderLocked();
      for (const auto& [name, topic] : d.topics) d.OnTopicLocked(name);
      d.ScanPublicationsLocked();
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

int DdsBus::Handle(int timeout_ms) {
  Impl& d = *impl_;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  int delivered = 0;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - std::chrono::steady_clock::now());
    const dds_return_t rc = dds_waitset_wait(d.waitset, nullptr, 0, std::max<int64_t>(left.count(), 0));
    if (rc < 0) throw BusError("DDS waitset failed on " + d.url + ": " + DdsError(rc));
    delivered += d.Drain();
    if (d.pending_error) {
      std::exception_ptr error = d.pending_error;
      d.pending_error = nullptr;
      std::rethrow_exception(error);
    }
    // A discovery event alone (no message yet) keeps waiting until the deadline.
    if (delivered > 0 || std::chrono::steady_clock::now() >= deadline) return delivered;
  }
}

}  // namespace fusecal
