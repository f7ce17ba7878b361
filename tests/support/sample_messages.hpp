// Messages the bus tests send (every transport's tests use the same ones).
#pragma once

#include <string>

#include "fusecal/status_t.hpp"

namespace fusecal::testing {

inline status_t MakeStatus(const std::string& name) {
  status_t s{};
  s.utime = 123;
  s.name = name;
  s.state = "running";
  s.num_counters = 1;
  s.counter_names = {"stations"};
  s.counter_values = {4};
  return s;
}

}  // namespace fusecal::testing
