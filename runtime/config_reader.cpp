#include "config_reader.hpp"

#include "strict_yaml.hpp"

#include <algorithm>
#include <sstream>

namespace fusecal {

Check<std::string> OneOf(std::vector<std::string> allowed) {
  return [allowed](const std::string& v) {
    if (std::find(allowed.begin(), allowed.end(), v) != allowed.end()) return std::string();
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    return "unknown value '" + v + "' (expected one of: " + list + ")";
  };
}

ConfigReader::ConfigReader(YAML::Node node, std::string source, std::string prefix)
    : node_(node), source_(std::move(source)), prefix_(std::move(prefix)) {  // a YAML::Node has no move
  if (node_ && !node_.IsNull() && !node_.IsMap())
    throw ConfigError(source_ + ": " + (prefix_.empty() ? std::string("top level") : prefix_) +
                      " must be a map of keys");
}

ConfigReader ConfigReader::FromFile(const std::string& path) {
  try {
    return ConfigReader(LoadStrictYamlFile(path), path);
  } catch (const YamlError& e) {
    throw ConfigError(e.what());
  }
}

ConfigReader ConfigReader::FromString(const std::string& text) {
  try {
    return ConfigReader(LoadStrictYaml(text, "<string>"), "<string>");
  } catch (const YamlError& e) {
    throw ConfigError(e.what());
  }
}

bool ConfigReader::Has(const std::string& key) const { return node_ && node_.IsMap() && node_[key]; }

ConfigReader ConfigReader::Child(const std::string& key) {
  read_.insert(key);
  if (!Has(key)) return ConfigReader(YAML::Node(), source_, PathOf(key));
  return ConfigReader(node_[key], source_, PathOf(key));
}

std::vector<ConfigReader> ConfigReader::Items(const std::string& key) {
  read_.insert(key);
  std::vector<ConfigReader> items;
  if (!Has(key)) return items;
  const YAML::Node list = node_[key];
  if (!list.IsSequence()) Fail(key, "must be a list");
  for (size_t k = 0; k < list.size(); ++k)
    items.emplace_back(list[k], source_, PathOf(key) + "[" + std::to_string(k) + "]");
  return items;
}

void ConfigReader::Finish() const {
  if (!node_ || !node_.IsMap()) return;
  std::vector<std::string> unknown;
  for (const auto& kv : node_) {
    const auto key = kv.first.as<std::string>();
    if (!read_.count(key)) unknown.push_back(PathOf(key));
  }
  if (unknown.empty()) return;
  std::ostringstream msg;
  msg << source_ << ": unknown key" << (unknown.size() > 1 ? "s" : "") << ":";
  for (const auto& k : unknown) msg << " '" << k << "'";
  throw ConfigError(msg.str());
}

void ConfigReader::FailSection(const std::string& what) const {
  throw ConfigError(source_ + ": " + (prefix_.empty() ? std::string("") : "'" + prefix_ + "': ") + what);
}

void ConfigReader::FailIfInvalid(const std::string& problem, const std::map<std::string, std::string>& fields) const {
  if (problem.empty()) return;
  for (const std::string& key : read_) {
    const auto renamed = fields.find(key);
    const std::string& field = renamed == fields.end() ? key : renamed->second;
    if (problem.compare(0, field.size(), field) != 0) continue;
    const std::string rest = problem.substr(field.size());
    if (rest.rfind(": ", 0) == 0) Fail(key, rest.substr(2));
    if (rest.rfind(" must", 0) == 0) Fail(key, rest.substr(1));
  }
  FailSection(problem);
}

void ConfigReader::Fail(const std::string& key, const std::string& what) const {
  throw ConfigError(source_ + ": '" + PathOf(key) + "' " + what);
}

}  // namespace fusecal
