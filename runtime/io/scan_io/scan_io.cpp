#include "runtime/io/scan_io/scan_io.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "runtime/io/scan_io/pcl_input_checks.hpp"

namespace fusecal {
namespace {

std::string Extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("scan file '" + path + "': " + what);
}

void RequireRegularFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) Fail(path, "does not exist");
  if (!std::filesystem::is_regular_file(path, ec)) Fail(path, "is not a regular file");
}

PointCloud ReadKittiBin(const std::string& path) {
  RequireRegularFile(path);
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) Fail(path, "cannot get its size: " + ec.message());
  if (bytes % 16 != 0)
    Fail(path, "truncated or corrupt KITTI .bin: " + std::to_string(bytes) +
                   " bytes is not a multiple of 16 (4 float32 per point)");
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail(path, "cannot be opened");
  const size_t n = bytes / 16;
  std::vector<float> raw(n * 4);
  if (n > 0 && !in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(bytes)))
    Fail(path, "read failed after " + std::to_string(in.gcount()) + " of " + std::to_string(bytes) + " bytes");
  PointCloud cloud;
  cloud.points.resize(n);
  cloud.intensity.resize(n);
  for (size_t i = 0; i < n; ++i) {
    cloud.points[i] = Eigen::Vector3f(raw[4 * i], raw[4 * i + 1], raw[4 * i + 2]);
    cloud.intensity[i] = raw[4 * i + 3];
  }
  return cloud;
}

const pcl::PCLPointField* FindField(const pcl::PCLPointCloud2& c, std::initializer_list<const char*> names) {
  for (const char* name : names)
    for (const pcl::PCLPointField& f : c.fields)
      if (f.name == name) return &f;
  return nullptr;
}

double ReadValue(const uint8_t* p, uint8_t datatype) {
  auto get = [p](auto zero) {
    decltype(zero) v;
    std::memcpy(&v, p, sizeof(v));
    return static_cast<double>(v);
  };
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return get(int8_t());
    case pcl::PCLPointField::UINT8:
      return get(uint8_t());
    case pcl::PCLPointField::INT16:
      return get(int16_t());
    case pcl::PCLPointField::UINT16:
      return get(uint16_t());
    case pcl::PCLPointField::INT32:
      return get(int32_t());
    case pcl::PCLPointField::UINT32:
      return get(uint32_t());
    case pcl::PCLPointField::FLOAT32:
      return get(float());
    case pcl::PCLPointField::FLOAT64:
      return get(double());
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

bool IsInteger(uint8_t datatype) {
  return datatype != pcl::PCLPointField::FLOAT32 && datatype != pcl::PCLPointField::FLOAT64;
}

size_t FieldSize(uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8:
      return 1;
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::UINT16:
      return 2;
    case pcl::PCLPointField::FLOAT64:
      return 8;
    default:
      return 4;
  }
}

// A beam index of any field type; one that no int16 holds (or NaN) is corrupt (converting it would be
// undefined behaviour: found by fuzzing, a float ring of 2.6e20).
int16_t RingIndex(const std::string& path, double value, size_t point) {
  if (!(value >= std::numeric_limits<int16_t>::min() && value <= std::numeric_limits<int16_t>::max()))
    Fail(path, "corrupt: the ring of point " + std::to_string(point) + " (" + std::to_string(value) +
                   ") is not a beam index");
  return static_cast<int16_t>(value);
}

PointCloud FromPcl(const std::string& path, const pcl::PCLPointCloud2& c) {
  const pcl::PCLPointField* x = FindField(c, {"x"});
  const pcl::PCLPointField* y = FindField(c, {"y"});
  const pcl::PCLPointField* z = FindField(c, {"z"});
  if (!x || !y || !z) Fail(path, "has no x, y, z fields");
  const pcl::PCLPointField* intensity = FindField(c, {"intensity", "reflectance", "i", "scalar_intensity"});
  const pcl::PCLPointField* ring = FindField(c, {"ring"});
  const pcl::PCLPointField* time = FindField(c, {"time", "time_offset_s", "t"});
  const size_t n = size_t(c.width) * c.height;
  if (c.data.size() < n * c.point_step) Fail(path, "corrupt: point data shorter than its header says");
  for (const pcl::PCLPointField* f : {x, y, z, intensity, ring, time})
    if (f && f->offset + FieldSize(f->datatype) > c.point_step) Fail(path, "corrupt: field outside the point");
  PointCloud cloud;
  cloud.points.resize(n);
  if (intensity) cloud.intensity.resize(n);
  if (ring) cloud.ring.resize(n);
  if (time) cloud.time_offset_s.resize(n);
  // Integer "t" (Ouster) is in nanoseconds.
  const double time_scale = time && IsInteger(time->datatype) ? 1e-9 : 1.0;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = c.data.data() + i * c.point_step;
    cloud.points[i] =
        Eigen::Vector3f(float(ReadValue(p + x->offset, x->datatype)), float(ReadValue(p + y->offset, y->datatype)),
                        float(ReadValue(p + z->offset, z->datatype)));
    if (intensity) cloud.intensity[i] = float(ReadValue(p + intensity->offset, intensity->datatype));
    if (ring) cloud.ring[i] = RingIndex(path, ReadValue(p + ring->offset, ring->datatype), i);
    if (time) cloud.time_offset_s[i] = float(time_scale * ReadValue(p + time->offset, time->datatype));
  }
  return cloud;
}

PointCloud ReadWithPcl(const std::string& path, bool ply) {
  RequireRegularFile(path);
  // PCL's readers trust their input (pcl_input_checks.hpp): the file is checked first.
  if ((ply ? scan_checks::CheckPly(path) : scan_checks::CheckPcd(path)) == 0) return PointCloud();
  pcl::PCLPointCloud2 c;
  int status = -1;
  try {
    if (ply) {
      pcl::PLYReader reader;
      status = reader.read(path, c);
    } else {
      pcl::PCDReader reader;
      status = reader.read(path, c);
    }
  } catch (const std::exception& e) {
    Fail(path, std::string("corrupt or unreadable: ") + e.what());
  }
  if (status < 0)
    Fail(path, std::string("corrupt or truncated ") + (ply ? ".ply" : ".pcd") + " file (PCL could not read it)");
  return FromPcl(path, c);
}

// Field layout written to .pcd and .ply: float x y z [intensity] [int16 ring] [float time].
struct Layout {
  bool intensity, ring, time;
  size_t Stride() const { return 12 + (intensity ? 4 : 0) + (ring ? 2 : 0) + (time ? 4 : 0); }
};

Layout LayoutOf(const std::string& path, const PointCloud& cloud) {
  const size_t n = cloud.size();
  auto check = [&](size_t size, const char* name) {
    if (size != 0 && size != n)
      Fail(path, std::string("cannot write: ") + name + " has " + std::to_string(size) + " entries for " +
                     std::to_string(n) + " points");
    return size == n && n > 0;
  };
  return {check(cloud.intensity.size(), "intensity"), check(cloud.ring.size(), "ring"),
          check(cloud.time_offset_s.size(), "time_offset_s")};
}

std::vector<char> PackPoints(const PointCloud& cloud, const Layout& layout) {
  std::vector<char> data(cloud.size() * layout.Stride());
  char* p = data.data();
  auto put = [&p](const void* v, size_t size) {
    std::memcpy(p, v, size);
    p += size;
  };
  for (size_t i = 0; i < cloud.size(); ++i) {
    put(cloud.points[i].data(), 12);
    if (layout.intensity) put(&cloud.intensity[i], 4);
    if (layout.ring) put(&cloud.ring[i], 2);
    if (layout.time) put(&cloud.time_offset_s[i], 4);
  }
  return data;
}

void WriteFile(const std::string& path, const std::string& header, const std::vector<char>& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) Fail(path, "cannot be opened for writing");
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  if (!data.empty()) out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out) Fail(path, "write failed");
}

void WritePcd(const std::string& path, const PointCloud& cloud) {
  const Layout l = LayoutOf(path, cloud);
  std::string fields = "x y z", sizes = "4 4 4", types = "F F F", counts = "1 1 1";
  auto add = [&](const char* name, const char* size, const char* type) {
    fields += std::string(" ") + name;
    sizes += std::string(" ") + size;
    types += std::string(" ") + type;
    counts += " 1";
  };
  if (l.intensity) add("intensity", "4", "F");
  if (l.ring) add("ring", "2", "I");
  if (l.time) add("time", "4", "F");
  const std::string n = std::to_string(cloud.size());
  const std::string header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " +
                             sizes + "\nTYPE " + types + "\nCOUNT " + counts + "\nWIDTH " + n +
                             "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA binary\n";
  WriteFile(path, header, PackPoints(cloud, l));
}

void WritePly(const std::string& path, const PointCloud& cloud) {
  const Layout l = LayoutOf(path, cloud);
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment fusecal scan\nelement vertex " +
                       std::to_string(cloud.size()) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (l.intensity) header += "property float intensity\n";
  if (l.ring) header += "property short ring\n";
  if (l.time) header += "property float time\n";
  header += "end_header\n";
  WriteFile(path, header, PackPoints(cloud, l));
}

void WriteKittiBin(const std::string& path, const PointCloud& cloud) {
  if (!cloud.intensity.empty() && cloud.intensity.size() != cloud.size())
    Fail(path, "cannot write: intensity has " + std::to_string(cloud.intensity.size()) + " entries for " +
                   std::to_string(cloud.size()) + " points");
  std::vector<char> data(cloud.size() * 16);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const float v[4] = {cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
                        cloud.intensity.empty() ? 0.0f : cloud.intensity[i]};
    std::memcpy(data.data() + 16 * i, v, 16);
  }
  WriteFile(path, "", data);
}

}  // namespace

PointCloud ReadScan(const std::string& path) {
  const std::string ext = Extension(path);
  if (ext == ".bin") return ReadKittiBin(path);
  if (ext == ".pcd") return ReadWithPcl(path, false);
  if (ext == ".ply") return ReadWithPcl(path, true);
  Fail(path, "unsupported extension '" + ext + "' (expected .bin, .pcd or .ply)");
}

void WriteScan(const std::string& path, const PointCloud& cloud) {
  const std::string ext = Extension(path);
  if (ext == ".bin") return WriteKittiBin(path, cloud);
  if (ext == ".pcd") return WritePcd(path, cloud);
  if (ext == ".ply") return WritePly(path, cloud);
  Fail(path, "unsupported extension '" + ext + "' (expected .bin, .pcd or .ply)");
}

}  // namespace fusecal
