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
    throw YamlError(At(source, mark) + ": a quoted value opens here and is never closed (" + std::string(1, first) +
                    " missing)");
}

// How many nodes the check may visit: a document without aliases has fewer nodes than characters; aliases
// (*name) visit their anchor's nodes again, and nested ten at a time 500 bytes would make 10^9 of them.
size_t NodeBudget(const std::string& text) { return 4 * text.size() + 1024; }

void CheckNode(const YAML::Node& node, const std::string& text, const std::string& source, int depth, size_t* budget) {
  if (depth > 64) throw YamlError(At(source, node.Mark()) + ": nested more than 64 levels deep");
  if (*budget == 0)
    throw YamlError(At(source, node.Mark()) + ": aliases (*name) expand the document to more than " +
                    std::to_string(NodeBudget(text)) + " nodes");
  --*budget;
  if (node.IsScalar()) {
    CheckScalar(node, text, source);
  } else if (node.IsSequence()) {
    for (const YAML::Node& child : node) CheckNode(child, text, source, depth + 1, budget);
  } else if (node.IsMap()) {
    std::map<std::string, int> first_line;
    for (auto it = node.begin(); it != node.end(); ++it) {
      CheckNode(it->first, text, source, depth + 1, budget);
      if (it->first.IsScalar()) {
        const auto [seen, fresh] = first_line.emplace(it->first.Scalar(), it->first.Mark().line + 1);
        if (!fresh)
          throw YamlError(At(source, it->first.Mark()) + ": duplicate key '" + it->first.Scalar() +
                          "' (first at line " + std::to_string(seen->second) + ")");
      }
      CheckNode(it->second, text, source, depth + 1, budget);
    }
  }
}

// Where a quote or a bracket can open a quoted scalar or a flow collection: at the start of a line or
// after an indicator (not inside a plain scalar such as "it's" or "a[1]").
bool AtTokenStart(const std::string& text, size_t i) {
  while (i > 0 && (text[i - 1] == ' ' || text[i - 1] == '\t')) --i;
  return i == 0 || std::string("\n:-,[{?").find(text[i - 1]) != std::string::npos;
}

// YAML 1.2 has no empty entry in a flow collection ("[a,,b]", "[,a]"); yaml-cpp accepts them and, given a
// few kilobytes of them nested, takes minutes (fuzzing: 245 s for 2.8 KB). Refused before it parses.
void CheckFlowEntries(const std::string& text, const std::string& source) {
  int depth = 0, line = 1;
  char previous = 0;  // the last character that is not blank, outside quotes and comments
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') continue;
    if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\t' || text[i - 1] == '\n')) {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
      continue;
    }
    if ((c == '"' || c == '\'') && AtTokenStart(text, i)) {
      const size_t close = ClosingQuote(text, i);
      if (close == std::string::npos) return;  // the parse says where the quote opens
      for (size_t k = i; k < close; ++k) line += text[k] == '\n';
      i = close;
      previous = c;
      continue;
    }
    if ((c == '[' || c == '{') && (depth > 0 || AtTokenStart(text, i))) ++depth;
    if ((c == ']' || c == '}') && depth > 0) --depth;
    if (depth > 0 && c == ',' && (previous == ',' || previous == '[' || previous == '{'))
      throw YamlError(source + ":" + std::to_string(line) + ": an empty entry in a flow collection ('" +
                      std::string(1, previous) + "' then ','): YAML has none");
    previous = c;
  }
}

}  // namespace

YAML::Node LoadStrictYaml(const std::string& text, const std::string& source) {
  CheckFlowEntries(text, source);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw YamlError(source + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  size_t budget = NodeBudget(text);
  CheckNode(root, text, source, 0, &budget);
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
