#include "stages/formats/rig_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "runtime/output_file.hpp"
#include "runtime/strict_yaml.hpp"
#include "stages/formats/yaml_transform.hpp"

namespace fusecal {

namespace {

using Vector12 = Eigen::Matrix<double, 12, 1>;

// Each estimate moved by its perturbation: R = R_hat Exp(d_r), t = t_hat + d_t (the covariance's own).
Isometry3 Perturbed(const Isometry3& T, const Eigen::Ref<const Eigen::Matrix<double, 6, 1>>& d) {
  return MakeIsometry(T.linear() * ExpSO3(d.head<3>()), T.translation() + d.tail<3>());
}

// T_to_from's perturbation from its estimate in the same convention.
Eigen::Matrix<double, 6, 1> PerturbationOf(const Isometry3& T, const Isometry3& T_hat) {
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = LogSO3(T_hat.linear().transpose() * T.linear());
  d.tail<3>() = T.translation() - T_hat.translation();
  return d;
}

Isometry3 Compose(const Isometry3& to_lidar, const Isometry3& from_lidar) { return to_lidar * from_lidar.inverse(); }

void EmitNumbers(YAML::Emitter& out, const std::string& key, const double* values, int n) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < n; ++i) out << values[i];
  out << YAML::EndSeq;
}

void EmitTransform(YAML::Emitter& out, const std::string& name, const Isometry3& T,
                   const std::optional<Matrix6>& covariance) {
  double m[16];
  ToRowMajor(T, m);
  EmitNumbers(out, name, m, 16);
  out << YAML::Key << name + "_std_dev" << YAML::Value << YAML::BeginMap;
  if (covariance) {
    const Eigen::Vector3d r = RotationStdDevDeg(*covariance), t = TranslationStdDevM(*covariance);
    EmitNumbers(out, "rotation_deg", r.data(), 3);
    EmitNumbers(out, "translation_m", t.data(), 3);
  } else {
    out << YAML::Key << "rotation_deg" << YAML::Value << YAML::Null;
    out << YAML::Key << "translation_m" << YAML::Value << YAML::Null;
  }
  out << YAML::EndMap;
  if (covariance) EmitNumbers(out, name + "_covariance", covariance->data(), 36);
}

std::string Where(const std::string& path, const std::string& key) { return path + ": '" + key + "'"; }

std::optional<Matrix6> ReadCovariance(const YAML::Node& root, const std::string& key) {
  const YAML::Node c = root[key];
  if (!c || !c.IsSequence() || c.size() != 36) return std::nullopt;
  Matrix6 covariance;
  for (int i = 0; i < 36; ++i) covariance.data()[i] = c[i].as<double>(std::nan(""));
  if (!covariance.allFinite()) return std::nullopt;
  return covariance;
}

}  // namespace

CameraToCamera DeriveCameraToCamera(const RigCameraResult& to, const RigCameraResult& from) {
  CameraToCamera c;
  c.to = to.camera;
  c.from = from.camera;
  c.T = Compose(to.T_camera_lidar, from.T_camera_lidar);
  if (!to.covariance || !from.covariance) return c;
  // First order: J = d(perturbation of T_to_from) / d(perturbations of both), by central differences
  // (the map is smooth and the perturbations small; 1e-6 rad or m keeps both truncation and rounding low).
  Eigen::Matrix<double, 6, 12> J;
  const double h = 1e-6;
  for (int k = 0; k < 12; ++k) {
    Vector12 d = Vector12::Zero();
    d(k) = h;
    const Isometry3 plus =
        Compose(Perturbed(to.T_camera_lidar, d.head<6>()), Perturbed(from.T_camera_lidar, d.tail<6>()));
    const Isometry3 minus =
        Compose(Perturbed(to.T_camera_lidar, -d.head<6>()), Perturbed(from.T_camera_lidar, -d.tail<6>()));
    J.col(k) = (PerturbationOf(plus, c.T) - PerturbationOf(minus, c.T)) / (2 * h);
  }
  Eigen::Matrix<double, 12, 12> both = Eigen::Matrix<double, 12, 12>::Zero();
  both.topLeftCorner<6, 6>() = *to.covariance;
  both.bottomRightCorner<6, 6>() = *from.covariance;
  const Matrix6 covariance = J * both * J.transpose();
  c.covariance = 0.5 * (covariance + covariance.transpose());
  return c;
}

RigResult MakeRigResult(std::vector<RigCameraResult> cameras) {
  RigResult rig;
  rig.cameras = std::move(cameras);
  for (size_t k = 1; k < rig.cameras.size(); ++k)
    rig.camera_to_camera.push_back(DeriveCameraToCamera(rig.cameras[k], rig.cameras.front()));
  return rig;
}

std::string RigToYaml(const RigResult& rig) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  out << YAML::BeginMap;
  out << YAML::Key << "cameras" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& c : rig.cameras) out << c.camera;
  out << YAML::EndSeq;
  out << YAML::Key << "std_dev_axes" << YAML::Value
      << "rotation_deg: about the source frame's axes (R = R_hat Exp(d)); translation_m: along the target camera's";
  for (const auto& c : rig.cameras) {
    const std::string name = "T_" + c.camera + "_lidar";
    EmitTransform(out, name, c.T_camera_lidar, c.covariance);
    out << YAML::Key << name + "_status" << YAML::Value << c.status;
    if (!c.file.empty()) out << YAML::Key << name + "_file" << YAML::Value << c.file;
  }
  if (!rig.camera_to_camera.empty())
    out << YAML::Key << "camera_to_camera" << YAML::Value
        << "T_<a>_<b> = T_<a>_lidar T_<b>_lidar^-1 (camera b into camera a); its covariance from both, taken as "
           "independent";
  for (const auto& c : rig.camera_to_camera) EmitTransform(out, "T_" + c.to + "_" + c.from, c.T, c.covariance);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void WriteRigFile(const std::string& path, const RigResult& rig) { WriteFileChecked(path, RigToYaml(rig)); }

bool IsRigFile(const std::string& path) {
  try {
    const YAML::Node root = LoadStrictYamlFile(path);
    return root.IsMap() && root["cameras"];
  } catch (const std::exception&) {
    return false;
  }
}

RigResult ReadRigFile(const std::string& path) {
  YAML::Node root;
  try {
    root = LoadStrictYamlFile(path);
  } catch (const YamlError& e) {
    throw std::runtime_error(std::string("rig result file ") + e.what());
  }
  const YAML::Node names = root.IsMap() ? root["cameras"] : YAML::Node();
  if (!names || !names.IsSequence() || names.size() == 0)
    throw std::runtime_error(Where(path, "cameras") + " must list the rig's cameras");
  std::vector<RigCameraResult> cameras;
  for (const auto& n : names) {
    RigCameraResult c;
    c.camera = n.as<std::string>("");
    const std::string name = "T_" + c.camera + "_lidar";
    c.T_camera_lidar = ReadYamlTransform(root, name, path);
    c.covariance = ReadCovariance(root, name + "_covariance");
    if (root[name + "_status"] && root[name + "_status"].IsScalar())
      c.status = root[name + "_status"].as<std::string>();
    if (root[name + "_file"] && root[name + "_file"].IsScalar()) c.file = root[name + "_file"].as<std::string>();
    cameras.push_back(std::move(c));
  }
  return MakeRigResult(std::move(cameras));  // the camera-to-camera ones derived again, as written
}

}  // namespace fusecal
