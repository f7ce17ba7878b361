// YAML as users write it, read strictly: yaml-cpp accepts a key given twice (the first value wins) and a
// quoted scalar left open (it runs to the end of the file, swallowing every key after it). Both are
// errors here, naming the file and the line, so a typo in a config or a result file cannot pass silently.
// So is an empty entry in a flow collection ("[a,,b]"), which YAML does not have and yaml-cpp, given many
// nested, takes minutes over, and aliases (*name) that expand the document beyond 4 nodes per character
// (a 500-byte "billion laughs" would take hours to check).
#pragma once

#include <yaml-cpp/yaml.h>

#include <stdexcept>
#include <string>

namespace fusecal {

class YamlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses `text`; `source` names it in messages ("<source>:<line>: duplicate key 'x' (first at line 3)").
YAML::Node LoadStrictYaml(const std::string& text, const std::string& source);

// Reads and parses the file at `path`: a missing file, a directory or an unreadable file is a YamlError
// naming the path, as is every syntax error.
YAML::Node LoadStrictYamlFile(const std::string& path);

}  // namespace fusecal
