#include "runtime/io/scan_io/pcl_input_checks.hpp"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace fusecal::scan_checks {
namespace {

using u64 = unsigned long long;

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("scan file '" + path + "': " + what);
}

// Bytes of the file after `header_bytes` (0 when the header reached the end: tellg() was -1).
u64 BytesAfter(const std::string& path, std::streamoff header_bytes) {
  std::error_code ec;
  const u64 file_bytes = static_cast<u64>(std::filesystem::file_size(path, ec));
  if (ec || header_bytes < 0 || static_cast<u64>(header_bytes) > file_bytes) return 0;
  return file_bytes - static_cast<u64>(header_bytes);
}

std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// ---- PCD ----

struct PcdHeader {
  std::vector<std::string> fields, sizes, types, counts;
  long long width = -1, height = 1, points = -1;
  std::string data;
  std::streamoff header_bytes = -1;
};

long long PcdNumber(const std::string& path, const std::string& line, const std::vector<std::string>& words) {
  try {
    if (words.size() != 2) throw std::invalid_argument(words[0]);
    size_t used = 0;
    const long long v = std::stoll(words[1], &used);
    // PCL holds WIDTH and HEIGHT in 32 bits; their product then fits in 64.
    if (used != words[1].size() || v < 0 || (words[0] != "POINTS" && v > 0xffffffffLL))
      throw std::invalid_argument(words[0]);
    return v;
  } catch (const std::exception&) {
    Fail(path, "corrupt .pcd header: bad " + words[0] + " line '" + line + "'");
  }
}

// PCL splits header lines at ' ', '\t' and '\r' but reads their numbers with >>, which also skips other
// white space: the two disagree on lines with control characters, and a blank line ends its header.
// COUNT values must be plain numbers (PCL leaves the rest of a line unread after a bad one).
void CheckPcdHeaderLine(const std::string& path, const std::string& line, int number) {
  const std::string where = "corrupt .pcd header: line " + std::to_string(number);
  for (unsigned char c : line)
    if ((c < 0x20 && c != '\t') || c == 0x7f) Fail(path, where + " holds a control character");
  const std::vector<std::string> words = Words(line);
  if (words.empty()) Fail(path, where + " is blank");
  if (words[0] == "COUNT")
    for (size_t i = 1; i < words.size(); ++i)
      if (words[i].find_first_not_of("0123456789") != std::string::npos)
        Fail(path, where + ": COUNT '" + words[i] + "' is not a number");
}

PcdHeader ReadPcdHeader(const std::string& path, std::ifstream& in) {
  PcdHeader h;
  std::string line;
  for (int n = 0; h.data.empty(); ++n) {
    if (n > 200 || !std::getline(in, line)) Fail(path, "corrupt .pcd: no DATA line in the header");
    if (line.empty()) continue;  // PCL skips only a line with nothing in it: it stops at "\r" or " "
    if (line.back() == '\r') line.pop_back();
    CheckPcdHeaderLine(path, line, n + 1);
    if (line[0] == '#') continue;
    const std::vector<std::string> words = Words(line);
    const std::string key = words.empty() ? "" : words[0];
    const std::vector<std::string> values(words.size() > 1 ? words.begin() + 1 : words.end(), words.end());
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS")
      h.fields = values;
    else if (key == "SIZE")
      h.sizes = values;
    else if (key == "TYPE")
      h.types = values;
    else if (key == "COUNT")
      h.counts = values;
    else if (key == "WIDTH")
      h.width = PcdNumber(path, line, words);
    else if (key == "HEIGHT")
      h.height = PcdNumber(path, line, words);
    else if (key == "POINTS")
      h.points = PcdNumber(path, line, words);
    else if (key == "DATA")
      h.data = values.empty() ? "?" : values[0];
    else
      Fail(path, "corrupt .pcd header: unknown line '" + line + "'");
  }
  h.header_bytes = in.tellg();
  return h;
}

// The bytes of one point; checks FIELDS, SIZE, TYPE, COUNT and WIDTH x HEIGHT = POINTS.
size_t PcdPointBytes(const std::string& path, PcdHeader& h) {
  if (h.fields.empty() || h.sizes.size() != h.fields.size() || h.types.size() != h.fields.size() ||
      (!h.counts.empty() && h.counts.size() != h.fields.size()))
    Fail(path, "corrupt .pcd header: FIELDS, SIZE, TYPE and COUNT do not match");
  if (h.width < 0) Fail(path, "corrupt .pcd header: WIDTH x HEIGHT is not POINTS");
  const u64 product = static_cast<u64>(h.width) * static_cast<u64>(h.height);
  if (h.points < 0) h.points = product > u64(INT64_MAX) ? -1 : static_cast<long long>(product);
  if (h.points < 0 || product != static_cast<u64>(h.points))
    Fail(path, "corrupt .pcd header: WIDTH x HEIGHT is not POINTS");
  size_t point_bytes = 0;
  for (size_t i = 0; i < h.fields.size(); ++i) {
    const std::string& size = h.sizes[i];
    const std::string& type = h.types[i];
    const long long count = h.counts.empty() ? 1 : std::atoll(h.counts[i].c_str());
    if ((size != "1" && size != "2" && size != "4" && size != "8") || (type != "I" && type != "U" && type != "F") ||
        (type == "F" && size != "4" && size != "8") || count < 1 || count > 100000)
      Fail(path, "corrupt .pcd header: field '" + h.fields[i] + "' has SIZE " + size + " TYPE " + type);
    point_bytes += size_t(std::stoi(size)) * size_t(count);
  }
  return point_bytes;
}

// binary_compressed: two uint32 sizes, then LZF data, which expands at most 88 times (a 3-byte
// back-reference of 264 bytes).
void CheckPcdCompressed(const std::string& path, std::ifstream& in, const PcdHeader& h, size_t point_bytes,
                        u64 available) {
  uint32_t sizes[2] = {0, 0};
  if (!in.read(reinterpret_cast<char*>(sizes), sizeof(sizes)) || 8 + u64(sizes[0]) > available)
    Fail(path, "truncated .pcd: compressed data shorter than its header says");
  const u64 points = static_cast<u64>(h.points);
  if (sizes[1] % point_bytes != 0 || sizes[1] / point_bytes != points)
    Fail(path, "corrupt .pcd: uncompressed size does not match POINTS");
  if (u64(sizes[1]) > 128 * u64(sizes[0]) + 128)
    Fail(path, "corrupt .pcd: " + std::to_string(sizes[0]) + " compressed bytes cannot hold " +
                   std::to_string(sizes[1]) + " (LZF expands at most 88 times)");
}

// PCL accepts a short last line ("possibly malformed"); a truncated file must not pass.
void CheckPcdAscii(const std::string& path, std::ifstream& in, const PcdHeader& h) {
  size_t values_per_point = 0;
  for (size_t i = 0; i < h.fields.size(); ++i) values_per_point += h.counts.empty() ? 1 : std::stoul(h.counts[i]);
  long long rows = 0;
  std::string line;
  while (std::getline(in, line)) {
    const size_t n = Words(line).size();
    if (n == 0) continue;
    if (n != values_per_point)
      Fail(path, "corrupt or truncated .pcd: point " + std::to_string(rows + 1) + " has " + std::to_string(n) +
                     " values instead of " + std::to_string(values_per_point));
    ++rows;
  }
  if (rows != h.points)
    Fail(path, "truncated .pcd: " + std::to_string(rows) + " of " + std::to_string(h.points) + " points");
}

// PCL's header loop does not stop at DATA: it goes on over empty lines, comments and VERSION lines, and
// a following line that starts with a header key is read as one (it may resize the cloud to any size).
void CheckNothingReadAsHeaderAfterData(const std::string& path, const PcdHeader& h) {
  if (h.header_bytes < 0) return;  // the DATA line ended the file
  std::ifstream in(path, std::ios::binary);
  in.seekg(h.header_bytes);
  static const char* kKeys[] = {"FIELDS", "COLUMNS", "SIZE",      "TYPE",   "COUNT",
                                "WIDTH",  "HEIGHT",  "VIEWPOINT", "POINTS", "DATA"};
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (first.empty()) return;
    if (first[0] == '#' || StartsWith(first, "VERSION")) continue;
    for (const char* key : kKeys)
      if (StartsWith(first, key))
        Fail(path, std::string("corrupt .pcd: the data after DATA starts a line with '") + key +
                       "', which PCL would read as a header line");
    return;
  }
}

// ---- PLY ----

struct PlyElement {
  std::string name;
  u64 count = 0;
  int properties = 0;
  bool has_list = false;
  u64 min_bytes = 0;  // binary: scalar properties plus the count of each list
};

// Bytes of a PLY scalar type, 0 for an unknown one.
int PlyTypeBytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" || type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

bool IsPlyIntegerType(const std::string& type) {
  return PlyTypeBytes(type) > 0 && type.find("float") == std::string::npos && type != "double";
}

void ReadPlyProperty(const std::string& path, const std::string& line, const std::vector<std::string>& w,
                     std::vector<PlyElement>* elements) {
  if (elements->empty()) Fail(path, "corrupt .ply header: property before any element: '" + line + "'");
  PlyElement& e = elements->back();
  ++e.properties;
  if (w.size() == 5 && w[1] == "list" && IsPlyIntegerType(w[2]) && PlyTypeBytes(w[3]) > 0) {
    e.has_list = true;
    e.min_bytes += u64(PlyTypeBytes(w[2]));
  } else if (w.size() == 3 && PlyTypeBytes(w[1]) > 0) {
    e.min_bytes += u64(PlyTypeBytes(w[1]));
  } else {
    Fail(path, "corrupt .ply header: bad property line '" + line + "'");
  }
}

std::vector<PlyElement> ReadPlyHeader(const std::string& path, std::ifstream& in, std::string* format) {
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") Fail(path, "not a PLY file (the first line is not 'ply')");
  std::vector<PlyElement> elements;
  for (int n = 0;; ++n) {
    if (n > 1000 || !std::getline(in, line)) Fail(path, "corrupt .ply: no end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> w = Words(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format" && w.size() == 3 && w[2] == "1.0" &&
        (w[1] == "ascii" || w[1] == "binary_little_endian" || w[1] == "binary_big_endian")) {
      *format = w[1];
    } else if (w[0] == "element" && w.size() == 3 && !w[2].empty() &&
               w[2].find_first_not_of("0123456789") == std::string::npos && w[2].size() <= 18) {
      elements.push_back({w[1], std::stoull(w[2])});
    } else if (w[0] == "property") {
      ReadPlyProperty(path, line, w, &elements);
    } else {
      Fail(path, "corrupt .ply header: bad line '" + line + "'");
    }
  }
  return elements;
}

}  // namespace

size_t CheckPcd(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot be opened");
  PcdHeader h = ReadPcdHeader(path, in);
  const size_t point_bytes = PcdPointBytes(path, h);
  const u64 available = BytesAfter(path, h.header_bytes);
  if (h.data == "binary") {
    if (static_cast<u64>(h.points) > available / point_bytes)
      Fail(path, "truncated .pcd: " + std::to_string(available) + " bytes of binary data for " +
                     std::to_string(h.points) + " points of " + std::to_string(point_bytes) + " bytes");
  } else if (h.data == "binary_compressed") {
    CheckPcdCompressed(path, in, h, point_bytes, available);
  } else if (h.data == "ascii") {
    CheckPcdAscii(path, in, h);
  } else {
    Fail(path, "corrupt .pcd header: DATA '" + h.data + "' (expected ascii, binary or binary_compressed)");
  }
  CheckNothingReadAsHeaderAfterData(path, h);
  return static_cast<size_t>(h.points);
}

size_t CheckPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot be opened");
  std::string format;
  const std::vector<PlyElement> elements = ReadPlyHeader(path, in, &format);
  if (format.empty()) Fail(path, "corrupt .ply header: no format line");
  const u64 available = BytesAfter(path, in.tellg());
  const PlyElement* vertex = nullptr;
  u64 binary_bytes = 0;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "range_grid") Fail(path, "organized .ply files (element range_grid) are not supported");
    if (e.count > 0 && e.properties == 0) Fail(path, "corrupt .ply header: element '" + e.name + "' has no property");
    // Every instance takes at least a byte per property (ascii: a digit; binary: see min_bytes).
    if (e.count > 0 && e.count > available / u64(e.properties))
      Fail(path, "corrupt or truncated .ply: element '" + e.name + "' declares " + std::to_string(e.count) +
                     " instances, the file has " + std::to_string(available) + " bytes after its header");
    binary_bytes += e.count * e.min_bytes;  // no overflow: count <= available, min_bytes <= 8 x properties
  }
  if (!vertex) Fail(path, "corrupt .ply: no vertex element");
  if (vertex->has_list) Fail(path, "corrupt .ply: a list property in the vertex element (PCL cannot read it)");
  if (format != "ascii" && binary_bytes > available)
    Fail(path, "truncated .ply: its elements need at least " + std::to_string(binary_bytes) + " bytes, the file has " +
                   std::to_string(available) + " after its header");
  return static_cast<size_t>(vertex->count);
}

}  // namespace fusecal::scan_checks
