// A PLY reader for scans whose header carries a pose ("matrix" lines), which general PLY readers
// reject. Vertex element only; ascii, binary_little_endian and binary_big_endian.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "runtime/io/importers/ishikawa.hpp"

namespace fusecal {

namespace {

struct Property {
  std::string name;
  std::string type;
  int size = 0;
};

int TypeSize(const std::string& type) {
  static const std::map<std::string, int> sizes{{"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},
                                                {"short", 2}, {"ushort", 2},  {"int16", 2},  {"uint16", 2},
                                                {"int", 4},   {"uint", 4},    {"int32", 4},  {"uint32", 4},
                                                {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

double Decode(const uint8_t* p, const std::string& type, bool swap) {
  uint8_t b[8];
  const int n = TypeSize(type);
  for (int i = 0; i < n; ++i) b[i] = swap ? p[n - 1 - i] : p[i];
  if (type == "float" || type == "float32") {
    float v;
    std::memcpy(&v, b, 4);
    return v;
  }
  if (type == "double" || type == "float64") {
    double v;
    std::memcpy(&v, b, 8);
    return v;
  }
  if (type == "char" || type == "int8") return int8_t(b[0]);
  if (type == "uchar" || type == "uint8") return b[0];
  if (type == "short" || type == "int16") {
    int16_t v;
    std::memcpy(&v, b, 2);
    return v;
  }
  if (type == "ushort" || type == "uint16") {
    uint16_t v;
    std::memcpy(&v, b, 2);
    return v;
  }
  if (type == "int" || type == "int32") {
    int32_t v;
    std::memcpy(&v, b, 4);
    return v;
  }
  uint32_t v;
  std::memcpy(&v, b, 4);
  return v;
}

// Indices of the vertex properties read (intensity: -1 when absent).
struct VertexColumns {
  int x = -1, y = -1, z = -1, intensity = -1;
};

VertexColumns FindVertexColumns(const std::string& path, const std::vector<Property>& props) {
  VertexColumns c;
  for (size_t k = 0; k < props.size(); ++k) {
    const auto& n = props[k].name;
    if (n == "x") c.x = int(k);
    if (n == "y") c.y = int(k);
    if (n == "z") c.z = int(k);
    if (c.intensity < 0 && (n == "intensity" || n == "confidence" || n == "reflectance" || n == "scalar_intensity"))
      c.intensity = int(k);
  }
  if (c.x < 0 || c.y < 0 || c.z < 0) throw std::runtime_error(path + ": vertices need x, y and z");
  return c;
}

// The pose of the "matrix" lines (each a column), none when there are none.
std::optional<Eigen::Matrix4d> PoseFromColumns(const std::string& path, const std::vector<Eigen::Vector4d>& columns) {
  if (columns.empty()) return std::nullopt;
  if (columns.size() != 4)
    throw std::runtime_error(path + ": needs 4 'matrix' lines, has " + std::to_string(columns.size()));
  Eigen::Matrix4d M;
  for (int c = 0; c < 4; ++c) M.col(c) = columns[c];
  return M;
}

// The numbers of one "matrix" line (a column of the pose).
Eigen::Vector4d MatrixColumn(const std::string& path, std::istringstream& words) {
  Eigen::Vector4d column;
  for (int i = 0; i < 4; ++i)
    if (!(words >> column[i])) throw std::runtime_error(path + ": 'matrix' line needs 4 numbers");
  return column;
}

// Bytes from the read position to the end of the file: more vertices than that cannot be there.
int64_t BytesLeft(std::ifstream& in) {
  const std::streamoff here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  in.seekg(here);
  return here < 0 || end < here ? 0 : int64_t(end - here);
}

}  // namespace

PosedScan ReadPlyWithPose(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line, format;
  std::getline(in, line);
  if (line.rfind("ply", 0) != 0) throw std::runtime_error(path + ": not a PLY file");
  std::vector<Property> props;
  std::vector<Eigen::Vector4d> columns;
  int64_t vertices = -1;
  bool in_vertex = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "end_header") break;
    if (word == "format") words >> format;
    if (word == "element") {
      std::string name;
      int64_t count = 0;
      words >> name >> count;
      if (name == "vertex") {
        if (vertices >= 0 || !props.empty()) throw std::runtime_error(path + ": two vertex elements");
        vertices = count;
        in_vertex = true;
      } else {
        if (vertices < 0)
          throw std::runtime_error(path + ": element '" + name + "' before the vertices is not supported");
        in_vertex = false;
      }
    }
    if (word == "property" && in_vertex) {
      Property p;
      words >> p.type >> p.name;
      p.size = TypeSize(p.type);
      if (p.size == 0) throw std::runtime_error(path + ": vertex property type '" + p.type + "' not supported");
      props.push_back(p);
    }
    if (word == "matrix") columns.push_back(MatrixColumn(path, words));
  }
  if (!in) throw std::runtime_error(path + ": header has no end_header");
  if (vertices < 0) throw std::runtime_error(path + ": no vertex element");
  const auto [ix, iy, iz, ii] = FindVertexColumns(path, props);
  PosedScan scan;
  scan.pose = PoseFromColumns(path, columns);
  // Not the declared count itself (found by fuzzing: "element vertex 666...6" reserved terabytes).
  scan.cloud.points.reserve(static_cast<size_t>(std::min(vertices, BytesLeft(in))));
  std::vector<double> values(props.size());
  if (format == "ascii") {
    for (int64_t v = 0; v < vertices; ++v) {
      for (auto& x : values)
        if (!(in >> x)) throw std::runtime_error(path + ": truncated at vertex " + std::to_string(v));
      scan.cloud.points.emplace_back(float(values[ix]), float(values[iy]), float(values[iz]));
      if (ii >= 0) scan.cloud.intensity.push_back(float(values[ii]));
    }
  } else if (format == "binary_little_endian" || format == "binary_big_endian") {
    int stride = 0;
    for (const auto& p : props) stride += p.size;
    std::vector<uint8_t> row(stride);
    const bool swap = format == "binary_big_endian";
    for (int64_t v = 0; v < vertices; ++v) {
      if (!in.read(reinterpret_cast<char*>(row.data()), stride))
        throw std::runtime_error(path + ": truncated at vertex " + std::to_string(v) + " of " +
                                 std::to_string(vertices));
      int offset = 0;
      for (size_t k = 0; k < props.size(); ++k) {
        values[k] = Decode(row.data() + offset, props[k].type, swap);
        offset += props[k].size;
      }
      scan.cloud.points.emplace_back(float(values[ix]), float(values[iy]), float(values[iz]));
      if (ii >= 0) scan.cloud.intensity.push_back(float(values[ii]));
    }
  } else {
    throw std::runtime_error(path + ": unknown PLY format '" + format + "'");
  }
  return scan;
}

}  // namespace fusecal
