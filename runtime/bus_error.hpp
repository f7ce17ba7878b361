// The error every bus throws: a URL it cannot use, a transport that cannot start, a message it cannot
// carry or decode.
#pragma once

#include <stdexcept>

namespace fusecal {

class BusError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace fusecal
