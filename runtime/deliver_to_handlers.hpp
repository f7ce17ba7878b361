// How the DDS and iceoryx buses hand one message to the subscriptions that match it.
#pragma once

#include <exception>

#include "runtime/bus.hpp"

namespace fusecal {

// Hands `raw` to each subscription of `matching` still active (a handler may unsubscribe a later one).
// A handler that throws keeps the message from none of the others: the first error is kept in
// `first_error` for Handle to rethrow once the batch is served (a message taken from the transport and
// not delivered would be lost without a count). Returns the handler calls.
template <typename SubscriptionPointers>
int DeliverToHandlers(const SubscriptionPointers& matching, const RawMessage& raw, std::exception_ptr& first_error) {
  int delivered = 0;
  for (const auto& sub : matching) {
    if (!sub->active) continue;
    ++delivered;
    try {
      sub->handler(raw);
    } catch (...) {
      if (!first_error) first_error = std::current_exception();
    }
  }
  return delivered;
}

}  // namespace fusecal
