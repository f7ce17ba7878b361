#include "stages/formats/camera_file.hpp"

#include <sstream>
#include <vector>

#include "runtime/config_reader.hpp"

namespace fusecal {

namespace {

CameraParams ReadCamera(ConfigReader& r) {
  CameraParams p;
  r.Require("model", &p.model, OneOf({"pinhole", "equidistant", "equirectangular"}));
  r.Require("width", &p.width, Positive<int>());
  r.Require("height", &p.height, Positive<int>());
  if (p.HasIntrinsics()) {
    r.Require("fx", &p.fx, Positive<double>());
    r.Require("fy", &p.fy, Positive<double>());
    r.Require("cx", &p.cx);
    r.Require("cy", &p.cy);
    std::vector<double> dist(5, 0.0);
    const bool fisheye = p.model == "equidistant";
    r.Get<std::vector<double>>("dist", &dist, [fisheye](const std::vector<double>& d) {
      if (fisheye) return d.size() == 4 ? std::string() : std::string("needs 4 numbers: k1 k2 k3 k4");
      return d.size() == 5 ? std::string() : std::string("needs 5 numbers: k1 k2 p1 p2 k3");
    });
    dist.resize(5, 0.0);
    for (int i = 0; i < 5; ++i) p.dist[i] = dist[i];
  }
  r.Finish();
  const std::string error = p.Validate();
  if (!error.empty()) r.Fail(error.substr(0, error.find(':')), error.substr(error.find(':') + 2));
  return p;
}

}  // namespace

CameraParams LoadCameraFile(const std::string& path) {
  ConfigReader r = ConfigReader::FromFile(path);
  return ReadCamera(r);
}

CameraParams ParseCameraYaml(const std::string& text) {
  ConfigReader r = ConfigReader::FromString(text);
  return ReadCamera(r);
}

std::string CameraToYaml(const CameraParams& p) {
  std::ostringstream out;
  out.precision(12);
  out << "model: " << p.model << "\nwidth: " << p.width << "\nheight: " << p.height << "\n";
  if (p.HasIntrinsics()) {
    out << "fx: " << p.fx << "\nfy: " << p.fy << "\ncx: " << p.cx << "\ncy: " << p.cy << "\ndist: [";
    const int count = p.model == "equidistant" ? 4 : 5;
    for (int i = 0; i < count; ++i) out << (i ? ", " : "") << p.dist[i];
    out << "]\n";
  }
  return out.str();
}

}  // namespace fusecal
