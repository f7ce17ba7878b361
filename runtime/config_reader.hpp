// Config loading with validation: every key is read through a ConfigReader, which knows the path of the
// node it reads ("lidar.beams"), rejects unknown keys and invalid values with a message naming the key.
//
//   ConfigReader r = ConfigReader::FromFile(path);   // strict YAML: no repeated key, no open quote
//   r.Get("max_range_m", &settings.max_range_m, Positive());
//   ConfigReader lidar = r.Child("lidar");   // optional section: empty reader if absent
//   r.Finish();                              // throws ConfigError on keys nobody read
//   r.FailIfInvalid(settings.Validate());    // ranges: the settings' own Validate() says what is allowed
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace fusecal {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A check on a value; returns an empty string when the value is fine, else what is wrong.
template <typename T>
using Check = std::function<std::string(const T&)>;

template <typename T>
Check<T> Positive() {
  return [](const T& v) { return v > T(0) ? std::string() : std::string("must be positive"); };
}
template <typename T>
Check<T> NonNegative() {
  return [](const T& v) { return v >= T(0) ? std::string() : std::string("must not be negative"); };
}
template <typename T>
Check<T> InRange(T lo, T hi) {
  return [lo, hi](const T& v) {
    return (v >= lo && v <= hi) ? std::string() : "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  };
}
Check<std::string> OneOf(std::vector<std::string> allowed);

class ConfigReader {
 public:
  // `source` names the file (or "<string>") in messages; `prefix` is the path of `node` inside it.
  ConfigReader(YAML::Node node, std::string source, std::string prefix = "");

  static ConfigReader FromFile(const std::string& path);
  static ConfigReader FromString(const std::string& text);

  bool Has(const std::string& key) const;

  // Reads `key` into *value when present (the default stays otherwise); with `required` a missing key
  // is an error. Throws ConfigError naming the key on a wrong type or a failed check.
  template <typename T>
  void Get(const std::string& key, T* value, Check<T> check = nullptr, bool required = false);

  template <typename T>
  void Require(const std::string& key, T* value, Check<T> check = nullptr) {
    Get(key, value, check, true);
  }

  // A nested map; an empty reader when absent. Its unknown keys are checked by its own Finish().
  ConfigReader Child(const std::string& key);
  // A list of maps, one reader per entry, named "key[0]", "key[1]", ...; empty when absent. Throws
  // ConfigError when the value is not a list, or an entry not a map.
  std::vector<ConfigReader> Items(const std::string& key);

  // Throws ConfigError listing every key of this node that was never read.
  void Finish() const;

  std::string PathOf(const std::string& key) const { return prefix_.empty() ? key : prefix_ + "." + key; }
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;
  // For checks on the section as a whole (e.g. a core's Validate() message, which names the field).
  [[noreturn]] void FailSection(const std::string& what) const;
  // Throws ConfigError for the message of a settings struct's Validate(); nothing when it is empty. When
  // the message is about a key of this node ("<field>: <what>" or "<field> must ..."), the error names the
  // key as Get() does ("'lidar_icp.min_fitness' must be in [0, 1]"), else the section. `fields` gives the
  // field Validate() names for a key where the two differ, e.g. {{"ratio", "matching.ratio"}}.
  void FailIfInvalid(const std::string& problem, const std::map<std::string, std::string>& fields = {}) const;

 private:
  YAML::Node node_;
  std::string source_;
  std::string prefix_;
  std::set<std::string> read_;
};

template <typename T>
void ConfigReader::Get(const std::string& key, T* value, Check<T> check, bool required) {
  read_.insert(key);
  if (!node_ || !node_.IsMap() || !node_[key]) {
    if (required) Fail(key, "is required");
    return;
  }
  T parsed;
  try {
    parsed = node_[key].template as<T>();
  } catch (const YAML::Exception&) {
    Fail(key, "has the wrong type");
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(parsed)) Fail(key, "must be finite");
  }
  if (check) {
    const std::string problem = check(parsed);
    if (!problem.empty()) Fail(key, problem);
  }
  *value = parsed;
}

}  // namespace fusecal
