#include "runtime/strict_yaml.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace fusecal {

namespace {

// The position of the quote that closes the quoted scalar opening at `open`, or npos when the text ends
// first. YAML escapes: a backslash in double quotes, a doubled quote in single quotes.
size_t ClosingQuote(const std::string& text, size_t open) {
  const char quote = text[open];
  for (size_t i = open + 1; i < text.size(); ++i) {
    if (quote == '"' && text[i] == '\\') {
      ++i;
    } else if (text[i] == quote) {
      if (quote == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;
        continue;
      }
      return i;
    }
  }
  return std::string::npos;
}

std::string At(const std::string& source, const YAML::Mark& mark) {
  return source + ":" + std::to_string(mark.line + 1);
}

void CheckScalar(const YAML::Node& node, const std::string& text, const std::string& source) {
  const YAML::Mark mark = node.Mark();
  if (mark.pos < 0 || static_cast<size_t>(mark.pos) >= text.size()) return;
  const char first = text[static_cast<size_t>(mark.pos)];
  if ((first == '"' || first == '\'') && ClosingQuote(text, static_cast<size_t>(mark.pos)) == std::string::npos)
    throw YamlError(At(source, mark) + ": a quoted value opens here and is never closed (" +
                    std::string(1, first) + " missing)");
}

void CheckNode(const YAML::Node& node, const std::string& text, const std::string& source, int depth) {
  if (depth > 64) throw YamlError(At(source, node.Mark()) + ": nested more than 64 levels deep");
  if (node.IsScalar()) {
    CheckScalar(node, text, source);
  } else if (node.IsSequence()) {
    for (const YAML::Node& child : node) CheckNode(child, text, source, depth + 1);
  } else if (node.IsMap()) {
    std::map<std::string, int> first_line;
    for (auto it = node.begin(); it != node.end(); ++it) {
      CheckNode(it->first, text, source, depth + 1);
      if (it->first.IsScalar()) {
        const auto [seen, fresh] = first_line.emplace(it->first.Scalar(), it->first.Mark().line + 1);
        if (!fresh)
          throw YamlError(At(source, it->first.Mark()) + ": duplicate key '" + it->first.Scalar() +
                          "' (first at line " + std::to_string(seen->second) + ")");
      }
      CheckNode(it->second, text, source, depth + 1);
    }
  }
}

}  // namespace

YAML::Node LoadStrictYaml(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw YamlError(source + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  CheckNode(root, text, source, 0);
  return root;
}

YAML::Node LoadStrictYamlFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw YamlError(path + ": is a directory, not a YAML file");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw YamlError(path + ": cannot open file");
  std::ostringstream text;
  text << file.rdbuf();
  if (file.bad()) throw YamlError(path + ": cannot read file");
  return LoadStrictYaml(text.str(), path);
}

}  // namespace fusecal
