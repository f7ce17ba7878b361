// The floor of the transport benchmark (row iceoryx-raw): a publisher and a subscriber written directly
// against iceoryx's C API, behind the Bus interface only so that the benchmark's probes drive it like the
// other transports. PublishRaw loans a chunk, copies the bytes in and publishes it; Handle waits on a
// waitset, takes each chunk, hands it to the handler in place and releases it. Nothing else: no header,
// no sequence numbers, no pattern subscriptions, no locks, no wait for a new publisher's subscribers (the
// probes' warm-up covers that). One channel per subscription, plain names only.
//
// URL: iceoryx-raw://?depth=N (subscriber queue, default 8). Needs a running RouDi.
#pragma once

#include <memory>
#include <string>

#include "runtime/bus.hpp"

namespace fusecal::bench {

// Whether `url` names this transport (iceoryx-raw://...).
bool IsRawIceoryxUrl(const std::string& url);

std::unique_ptr<Bus> MakeRawIceoryxBus(const std::string& url);

}  // namespace fusecal::bench
