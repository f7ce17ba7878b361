// The result vocabulary of the stage cores. Every core result says usable(): the caller may use what it
// holds. When it is not usable, failure_reason says why: a code of the core's own enum class (whose
// kNone means usable) and the text that logs, messages and files carry.
//
//   enum class RegistrationFailure { kNone, kNotRun, kTooFewPoints, ... };
//   struct RegistrationResult {
//     Failure<RegistrationFailure> failure_reason{RegistrationFailure::kNotRun, {}};
//     bool usable() const { return failure_reason.code == RegistrationFailure::kNone; }
//   };
#pragma once

#include <ostream>
#include <string>

namespace fusecal {

template <typename Code>
struct Failure {
  Code code = Code::kNone;
  std::string text;  // empty when code is kNone
};

// A failure prints as its text.
template <typename Code>
std::ostream& operator<<(std::ostream& out, const Failure<Code>& failure) {
  return out << failure.text;
}

}  // namespace fusecal
