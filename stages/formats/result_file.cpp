#include "stages/formats/result_file.hpp"

#include "stages/foundation/extrinsic_error.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "runtime/output_file.hpp"
#include "runtime/strict_yaml.hpp"
#include "stages/formats/yaml_transform.hpp"
#include "stages/foundation/observed_covariance.hpp"

namespace fusecal {

namespace {

void EmitVector(YAML::Emitter& out, const std::string& key, const std::vector<double>& values) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (double v : values) out << v;
  out << YAML::EndSeq;
}

std::vector<double> ToVector(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

// What the motions observe, when a direction is unobservable: std_dev there carries the huge variance
// of that direction on every axis it is not orthogonal to.
void EmitObservedPart(YAML::Emitter& out, const CalibrationResult& r) {
  const ObservedUncertainty observed =
      ObservedPart(*r.covariance, r.T_camera_lidar.linear(), *r.unobservable_direction);
  out << YAML::Key << "std_dev_observed" << YAML::Value << YAML::BeginMap;
  EmitVector(out, "rotation_deg", ToVector(observed.rotation_std_deg));
  EmitVector(out, "translation_m", ToVector(observed.translation_std_m));
  out << YAML::Key << "rotation_max_deg" << YAML::Value << observed.max_rotation_std_deg;
  out << YAML::Key << "translation_max_m" << YAML::Value << observed.max_translation_std_m;
  out << YAML::Key << "projected_out" << YAML::Value
      << (observed.rotation_projected && observed.translation_projected
              ? "rotation about and translation along unobservable_direction"
          : observed.rotation_projected    ? "rotation about unobservable_direction"
          : observed.translation_projected ? "translation along unobservable_direction"
                                           : "nothing (no variance marks it unobserved)");
  out << YAML::EndMap;
}

void EmitBody(YAML::Emitter& out, const CalibrationResult& r) {
  out.SetDoublePrecision(12);
  double m[16];
  ToRowMajor(r.T_camera_lidar, m);
  EmitVector(out, "T_camera_lidar", std::vector<double>(m, m + 16));
  EmitVector(out, "translation_m", ToVector(r.T_camera_lidar.translation()));
  const Eigen::Quaterniond q(r.T_camera_lidar.linear());
  EmitVector(out, "rotation_quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()});
  EmitVector(out, "rotation_rpy_deg", ToVector(RpyFromRotation(r.T_camera_lidar.linear()) * 180.0 / M_PI));
  out << YAML::Key << "std_dev_axes" << YAML::Value
      << "rotation_deg: about the LiDAR axes (R = R_hat Exp(d)); translation_m: along the camera axes";
  out << YAML::Key << "std_dev" << YAML::Value << YAML::BeginMap;
  if (r.covariance) {
    EmitVector(out, "rotation_deg", ToVector(RotationStdDevDeg(*r.covariance)));
    EmitVector(out, "translation_m", ToVector(TranslationStdDevM(*r.covariance)));
  } else {
    out << YAML::Key << "rotation_deg" << YAML::Value << YAML::Null;
    out << YAML::Key << "translation_m" << YAML::Value << YAML::Null;
  }
  out << YAML::EndMap;
  if (r.covariance && r.unobservable_direction) EmitObservedPart(out, r);
  if (r.covariance) {
    EmitVector(out, "covariance", std::vector<double>(r.covariance->data(), r.covariance->data() + 36));
  }
  out << YAML::Key << "status" << YAML::Value << r.status;
  out << YAML::Key << "observability" << YAML::Value << r.observability;
  if (r.unobservable_direction) EmitVector(out, "unobservable_direction", ToVector(*r.unobservable_direction));
  out << YAML::Key << "motions_used" << YAML::Value << YAML::Flow << r.motions_used;
  out << YAML::Key << "motions_rejected" << YAML::Value << r.motions_rejected;
  out << YAML::Key << "residual_rms" << YAML::Value << r.residual_rms;
  for (const auto& [key, value] : r.extra) out << YAML::Key << key << YAML::Value << value;
}

void EmitChanges(YAML::Emitter& out, const std::vector<ExtrinsicChangeRecord>& changes) {
  out << YAML::Key << "changes" << YAML::Value << YAML::BeginSeq;
  for (const auto& c : changes) {
    out << YAML::BeginMap;
    out << YAML::Key << "after_station" << YAML::Value << c.after_station;
    out << YAML::Key << "decided_at_station" << YAML::Value << c.decided_at_station;
    out << YAML::Key << "rotation_deg" << YAML::Value << c.rotation_deg;
    out << YAML::Key << "rotation_std_deg" << YAML::Value << c.rotation_std_deg;
    out << YAML::Key << "translation_m" << YAML::Value << c.translation_m;
    out << YAML::Key << "translation_std_m" << YAML::Value << c.translation_std_m;
    double m[16];
    ToRowMajor(c.T_before, m);
    EmitVector(out, "T_camera_lidar_before", std::vector<double>(m, m + 16));
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

}  // namespace

ExtrinsicChangeRecord MakeChangeRecord(int after_station, int decided_at_station, const Isometry3& before,
                                       const Matrix6& covariance_before, const Isometry3& after,
                                       const Matrix6& covariance_after) {
  ExtrinsicChangeRecord r;
  r.after_station = after_station;
  r.decided_at_station = decided_at_station;
  r.T_before = before;
  const ExtrinsicChangeSize size = SizeOfChange(before, covariance_before, after, covariance_after);
  r.rotation_deg = size.rotation_deg;
  r.rotation_std_deg = size.rotation_std_deg;
  r.translation_m = size.translation_m;
  r.translation_std_m = size.translation_std_m;
  return r;
}

Eigen::Vector3d RotationStdDevDeg(const Matrix6& c) {
  return c.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt() * 180.0 / M_PI;
}

Eigen::Vector3d TranslationStdDevM(const Matrix6& c) { return c.diagonal().tail<3>().cwiseMax(0.0).cwiseSqrt(); }

std::string ResultToYaml(const CalibrationResult& result, const CalibrationResult* initial) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  EmitBody(out, result);
  if (result.changes) EmitChanges(out, *result.changes);
  if (initial) {
    out << YAML::Key << "initial" << YAML::Value << YAML::BeginMap;
    EmitBody(out, *initial);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void WriteResultFile(const std::string& path, const CalibrationResult& result, const CalibrationResult* initial) {
  WriteFileChecked(path, ResultToYaml(result, initial));
}

Isometry3 ReadYamlTransform(const YAML::Node& root, const std::string& key, const std::string& path) {
  const YAML::Node matrix = root.IsMap() ? root[key] : YAML::Node();
  if (!matrix || !matrix.IsSequence() || matrix.size() != 16)
    throw std::runtime_error(path + ": '" + key + "' must be a list of 16 numbers (row-major 4x4)");
  double m[16];
  try {
    for (int i = 0; i < 16; ++i) m[i] = matrix[i].as<double>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": '" + key + "' holds something that is not a number");
  }
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = m[i];
  Isometry3 raw;
  raw.matrix() = M;
  if (!IsValidTransform(raw, 1e-4) || std::abs(M(3, 3) - 1) > 1e-9 || M.row(3).head<3>().norm() > 1e-9)
    throw std::runtime_error(path + ": '" + key +
                             "' is not a rigid transform (rotation not orthonormal, non-finite, or last row not "
                             "0 0 0 1)");
  return FromRowMajor(m);
}

CalibrationResult ReadResultFile(const std::string& path) {
  YAML::Node root;
  try {
    root = LoadStrictYamlFile(path);
  } catch (const YamlError& e) {
    throw std::runtime_error(std::string("result file ") + e.what());
  }
  if (root.IsMap() && !root["T_camera_lidar"] && root["cameras"])
    throw std::runtime_error(path +
                             " is the result of a rig of several cameras (T_<camera>_lidar): give one camera's, "
                             "<camera>/extrinsic.yaml beside it");
  CalibrationResult result;
  result.T_camera_lidar = ReadYamlTransform(root, "T_camera_lidar", path);
  auto read_string = [&](const char* key, std::string* out) {
    if (root[key] && root[key].IsScalar()) *out = root[key].as<std::string>();
  };
  read_string("status", &result.status);
  read_string("observability", &result.observability);
  if (root["residual_rms"] && root["residual_rms"].IsScalar())
    result.residual_rms = root["residual_rms"].as<double>(0.0);
  const YAML::Node direction = root["unobservable_direction"];
  if (direction && direction.IsSequence() && direction.size() == 3) {
    const Eigen::Vector3d d(direction[0].as<double>(0.0), direction[1].as<double>(0.0), direction[2].as<double>(0.0));
    if (d.allFinite() && d.norm() > 0.5) result.unobservable_direction = d.normalized();
  }
  if (root["covariance"] && root["covariance"].IsSequence() && root["covariance"].size() == 36) {
    Matrix6 c;
    for (int i = 0; i < 36; ++i) c.data()[i] = root["covariance"][i].as<double>();
    result.covariance = c;
  }
  return result;
}

}  // namespace fusecal
