#include "stages/formats/extrinsic_formats.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "runtime/strict_yaml.hpp"

namespace fusecal {

namespace {

std::string ExportKitti(const CalibrationResult& r) {
  std::ostringstream out;
  out.precision(12);
  out << "calib_time: exported by fusecal (T_camera_lidar: p_camera = R * p_lidar + T)\nR:";
  const Eigen::Matrix3d R = r.T_camera_lidar.linear();
  for (int i = 0; i < 9; ++i) out << " " << R(i / 3, i % 3);
  out << "\nT:";
  for (int i = 0; i < 3; ++i) out << " " << r.T_camera_lidar.translation()[i];
  out << "\n";
  return out.str();
}

std::string ExportRos(const CalibrationResult& r, const ExportFrames& frames) {
  const Eigen::Quaterniond q(r.T_camera_lidar.linear());
  const Eigen::Vector3d t = r.T_camera_lidar.translation();
  std::ostringstream out;
  out.precision(12);
  out << t.x() << " " << t.y() << " " << t.z() << " " << q.x() << " " << q.y() << " " << q.z() << " " << q.w() << " "
      << frames.parent << " " << frames.child << "\n";
  return out.str();
}

std::string ExportJson(const CalibrationResult& r) {
  double m[16];
  ToRowMajor(r.T_camera_lidar, m);
  const Eigen::Quaterniond q(r.T_camera_lidar.linear());
  const Eigen::Vector3d t = r.T_camera_lidar.translation();
  nlohmann::ordered_json j{{"T_camera_lidar", std::vector<double>(m, m + 16)},
                           {"translation_m", {t.x(), t.y(), t.z()}},
                           {"rotation_quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                           {"status", r.status},
                           {"observability", r.observability}};
  if (r.covariance) {
    const Eigen::Vector3d sr = RotationStdDevDeg(*r.covariance), st = TranslationStdDevM(*r.covariance);
    j["std_dev"] = {{"rotation_deg", {sr.x(), sr.y(), sr.z()}}, {"translation_m", {st.x(), st.y(), st.z()}}};
  }
  return j.dump(2) + "\n";
}

std::string ExportOpenCv(const CalibrationResult& r) {
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  cv::Mat T, R, t;
  cv::eigen2cv(Eigen::Matrix4d(r.T_camera_lidar.matrix()), T);
  cv::eigen2cv(Eigen::Matrix3d(r.T_camera_lidar.linear()), R);
  cv::eigen2cv(Eigen::Vector3d(r.T_camera_lidar.translation()), t);
  fs << "T_camera_lidar" << T << "R" << R << "t" << t;
  fs << "status" << r.status << "observability" << r.observability;
  if (r.covariance) {
    cv::Mat sr, st;
    cv::eigen2cv(Eigen::Vector3d(RotationStdDevDeg(*r.covariance)), sr);
    cv::eigen2cv(Eigen::Vector3d(TranslationStdDevM(*r.covariance)), st);
    fs << "std_dev_rotation_deg" << sr << "std_dev_translation_m" << st;
  }
  return fs.releaseAndGetString();
}

std::string ExportUrdf(const CalibrationResult& r, const ExportFrames& frames) {
  const Eigen::Vector3d t = r.T_camera_lidar.translation(), rpy = RpyFromRotation(r.T_camera_lidar.linear());
  std::ostringstream out;
  out.precision(15);
  out << "<?xml version=\"1.0\"?>\n"
      << "<!-- T_camera_lidar by fusecal (" << r.status << ", " << r.observability << "): the pose of the LiDAR frame\n"
      << "     in the camera's optical frame (x right, y down, z forward). Paste the joint into the robot's URDF\n"
      << "     or xacro where the LiDAR link has no other parent; otherwise compose it with the camera's pose. -->\n"
      << "<robot name=\"fusecal_extrinsic\">\n"
      << "  <link name=\"" << frames.parent << "\"/>\n"
      << "  <link name=\"" << frames.child << "\"/>\n"
      << "  <joint name=\"" << frames.parent << "_to_" << frames.child << "\" type=\"fixed\">\n"
      << "    <parent link=\"" << frames.parent << "\"/>\n"
      << "    <child link=\"" << frames.child << "\"/>\n"
      << "    <origin xyz=\"" << t.x() << " " << t.y() << " " << t.z() << "\" rpy=\"" << rpy.x() << " " << rpy.y()
      << " " << rpy.z() << "\"/>\n"
      << "  </joint>\n"
      << "</robot>\n";
  return out.str();
}

// The three numbers of attribute `name` of the first <origin> element.
Eigen::Vector3d UrdfOriginAttribute(const std::string& text, const std::string& name) {
  const size_t origin = text.find("<origin");
  if (origin == std::string::npos || text.find("<joint") == std::string::npos)
    throw std::runtime_error("urdf: no <joint> with an <origin>");
  const size_t end = text.find('>', origin);
  const std::string element = text.substr(origin, end == std::string::npos ? std::string::npos : end - origin);
  const size_t at = element.find(" " + name + "=\"");
  if (at == std::string::npos) throw std::runtime_error("urdf: <origin> has no " + name + "=\"...\"");
  std::istringstream values(element.substr(at + name.size() + 3));
  Eigen::Vector3d v;
  if (!(values >> v.x() >> v.y() >> v.z()) || !v.allFinite())
    throw std::runtime_error("urdf: <origin> " + name + " needs three numbers");
  return v;
}

void CheckFrameName(const std::string& name) {
  if (name.empty() || name.find_first_of(" \t\n\"'<>&") != std::string::npos)
    throw std::invalid_argument("frame name '" + name + "': must be non-empty, without spaces, quotes, <, > or &");
}

// Reads `count` numbers after "key:" on its own line.
std::vector<double> KittiLine(const std::string& text, const std::string& key, size_t count) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    std::istringstream values(line.substr(key.size() + 1));
    std::vector<double> v;
    double x;
    while (values >> x) v.push_back(x);
    if (v.size() != count)
      throw std::runtime_error("kitti: '" + key + "' needs " + std::to_string(count) + " numbers, has " +
                               std::to_string(v.size()));
    return v;
  }
  throw std::runtime_error("kitti: no '" + key + ":' line");
}

Isometry3 Checked(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::string& format) {
  const Isometry3 T = MakeIsometry(R, t);
  if (!IsValidTransform(T, 1e-5)) throw std::runtime_error(format + ": not a rigid transform");
  return MakeIsometry(NearestRotation(R), t);
}

}  // namespace

const std::vector<std::string>& ExportFormats() {
  static const std::vector<std::string> formats{"kitti", "ros-static-tf", "json", "opencv-yaml", "urdf"};
  return formats;
}

std::string ExportRig(const RigResult& rig, const std::string& format, const ExportFrames& frames) {
  ExportExtrinsic(CalibrationResult{}, format, frames);  // the same checks of the format and frame names
  std::ostringstream out;
  out.precision(12);
  if (format == "kitti") {
    out << "calib_time: exported by fusecal (per camera: p_camera = R_<camera> * p_lidar + T_<camera>)\n";
    for (const auto& c : rig.cameras) {
      const Eigen::Matrix3d R = c.T_camera_lidar.linear();
      out << "R_" << c.camera << ":";
      for (int i = 0; i < 9; ++i) out << " " << R(i / 3, i % 3);
      out << "\nT_" << c.camera << ":";
      for (int i = 0; i < 3; ++i) out << " " << c.T_camera_lidar.translation()[i];
      out << "\n";
    }
    return out.str();
  }
  if (format == "ros-static-tf" || format == "urdf") {
    if (format == "urdf")
      out << "<?xml version=\"1.0\"?>\n<!-- A rig calibrated by fusecal: the pose of each camera's optical frame (x "
             "right, y "
             "down, z forward)\n     in the LiDAR frame. -->\n<robot name=\"fusecal_rig\">\n  <link name=\""
          << frames.child << "\"/>\n";
    for (const auto& c : rig.cameras) {
      ExportExtrinsic(CalibrationResult{}, format, ExportFrames{c.camera, frames.child});  // the camera's name
      const Isometry3 T = c.T_camera_lidar.inverse();                                      // T_lidar_camera
      const Eigen::Vector3d t = T.translation();
      if (format == "ros-static-tf") {
        const Eigen::Quaterniond q(T.linear());
        out << t.x() << " " << t.y() << " " << t.z() << " " << q.x() << " " << q.y() << " " << q.z() << " " << q.w()
            << " " << frames.child << " " << c.camera << "\n";
        continue;
      }
      const Eigen::Vector3d rpy = RpyFromRotation(T.linear());
      out << "  <link name=\"" << c.camera << "\"/>\n  <joint name=\"" << frames.child << "_to_" << c.camera
          << "\" type=\"fixed\">\n    <parent link=\"" << frames.child << "\"/>\n    <child link=\"" << c.camera
          << "\"/>\n    <origin xyz=\"" << t.x() << " " << t.y() << " " << t.z() << "\" rpy=\"" << rpy.x() << " "
          << rpy.y() << " " << rpy.z() << "\"/>\n  </joint>\n";
    }
    if (format == "urdf") out << "</robot>\n";
    return out.str();
  }
  const auto std_json = [](const std::optional<Matrix6>& covariance) {
    if (!covariance) return nlohmann::ordered_json();
    const Eigen::Vector3d sr = RotationStdDevDeg(*covariance), st = TranslationStdDevM(*covariance);
    return nlohmann::ordered_json{{"rotation_deg", {sr.x(), sr.y(), sr.z()}},
                                  {"translation_m", {st.x(), st.y(), st.z()}}};
  };
  if (format == "json") {
    nlohmann::ordered_json j;
    for (const auto& c : rig.cameras) {
      double m[16];
      ToRowMajor(c.T_camera_lidar, m);
      j["T_" + c.camera + "_lidar"] = {
          {"T", std::vector<double>(m, m + 16)}, {"std_dev", std_json(c.covariance)}, {"status", c.status}};
    }
    for (const auto& c : rig.camera_to_camera) {
      double m[16];
      ToRowMajor(c.T, m);
      j["T_" + c.to + "_" + c.from] = {{"T", std::vector<double>(m, m + 16)}, {"std_dev", std_json(c.covariance)}};
    }
    return j.dump(2) + "\n";
  }
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);  // opencv-yaml
  const auto write = [&fs](const std::string& name, const Isometry3& T, const std::optional<Matrix6>& covariance) {
    cv::Mat M;
    cv::eigen2cv(Eigen::Matrix4d(T.matrix()), M);
    fs << name << M;
    if (!covariance) return;
    cv::Mat sr, st;
    cv::eigen2cv(Eigen::Vector3d(RotationStdDevDeg(*covariance)), sr);
    cv::eigen2cv(Eigen::Vector3d(TranslationStdDevM(*covariance)), st);
    fs << name + "_std_dev_rotation_deg" << sr << name + "_std_dev_translation_m" << st;
  };
  for (const auto& c : rig.cameras) write("T_" + c.camera + "_lidar", c.T_camera_lidar, c.covariance);
  for (const auto& c : rig.camera_to_camera) write("T_" + c.to + "_" + c.from, c.T, c.covariance);
  return fs.releaseAndGetString();
}

std::string ExportExtrinsic(const CalibrationResult& result, const std::string& format, const ExportFrames& frames) {
  CheckFrameName(frames.parent);
  CheckFrameName(frames.child);
  if (format == "kitti") return ExportKitti(result);
  if (format == "ros-static-tf") return ExportRos(result, frames);
  if (format == "json") return ExportJson(result);
  if (format == "opencv-yaml") return ExportOpenCv(result);
  if (format == "urdf") return ExportUrdf(result, frames);
  throw std::invalid_argument("unknown export format '" + format +
                              "' (expected kitti, ros-static-tf, json, opencv-yaml or urdf)");
}

Isometry3 ParseExportedExtrinsic(const std::string& text, const std::string& format) {
  if (format == "kitti") {
    const auto r = KittiLine(text, "R", 9), t = KittiLine(text, "T", 3);
    Eigen::Matrix3d R;
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = r[i];
    return Checked(R, Eigen::Vector3d(t[0], t[1], t[2]), format);
  }
  if (format == "ros-static-tf") {
    std::istringstream in(text);
    double v[7];
    for (double& x : v)
      if (!(in >> x)) throw std::runtime_error("ros-static-tf: expected x y z qx qy qz qw parent child");
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (std::abs(q.norm() - 1.0) > 1e-6) throw std::runtime_error("ros-static-tf: quaternion is not unit");
    return Checked(q.toRotationMatrix(), Eigen::Vector3d(v[0], v[1], v[2]), format);
  }
  if (format == "json") {
    const auto j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.contains("T_camera_lidar") || j["T_camera_lidar"].size() != 16)
      throw std::runtime_error("json: needs T_camera_lidar with 16 numbers");
    const auto m = j["T_camera_lidar"].get<std::vector<double>>();
    Eigen::Matrix3d R;
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = m[(i / 3) * 4 + i % 3];
    return Checked(R, Eigen::Vector3d(m[3], m[7], m[11]), format);
  }
  if (format == "opencv-yaml") {
    // OpenCV's reader lets a repeated key pass (the first wins): check the text strictly first, with
    // OpenCV's "%YAML:1.0" directive (not YAML 1.2 syntax) blanked out so that line numbers hold.
    std::string yaml = text;
    if (yaml.rfind("%YAML:", 0) == 0) yaml.replace(0, std::min(yaml.find('\n'), yaml.size()), "");
    // OpenCV allocates rows x cols before it looks at the data (fuzzing: 64 GB for "rows: ("): the
    // matrix must say 4 x 4 here first.
    try {
      const YAML::Node matrix = LoadStrictYaml(yaml, "opencv-yaml")["T_camera_lidar"];
      if (!matrix.IsMap() || !matrix["rows"] || !matrix["cols"] || matrix["rows"].as<std::string>() != "4" ||
          matrix["cols"].as<std::string>() != "4")
        throw std::runtime_error("opencv-yaml: needs T_camera_lidar as an opencv-matrix with rows: 4 and cols: 4");
    } catch (const YamlError& e) {
      throw std::runtime_error(e.what());
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(std::string("opencv-yaml: ") + e.what());
    }
    cv::Mat T;
    try {
      cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
      fs["T_camera_lidar"] >> T;
    } catch (const cv::Exception& e) {
      throw std::runtime_error("opencv-yaml: not readable by OpenCV's YAML reader (" + e.err + ")");
    }
    if (T.rows != 4 || T.cols != 4) throw std::runtime_error("opencv-yaml: needs a 4x4 T_camera_lidar");
    Eigen::Matrix4d M;
    cv::cv2eigen(T, M);
    return Checked(M.topLeftCorner<3, 3>(), M.topRightCorner<3, 1>(), format);
  }
  if (format == "urdf") {
    const Eigen::Vector3d xyz = UrdfOriginAttribute(text, "xyz"), rpy = UrdfOriginAttribute(text, "rpy");
    return Checked(RotationFromRpy(rpy.x(), rpy.y(), rpy.z()), xyz, format);
  }
  throw std::invalid_argument("unknown format '" + format + "'");
}

}  // namespace fusecal
