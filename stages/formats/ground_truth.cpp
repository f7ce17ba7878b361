#include "stages/formats/ground_truth.hpp"

#include "stages/formats/rig_file.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/result_file.hpp"

namespace fusecal {

namespace {

// What keeps a row-major 4x4 from being a rigid transform; empty when it is one.
std::string RigidTransformProblem(const double m[16]) {
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = m[i];
  if (!M.allFinite()) return "it holds NaN or infinity";
  if (M.isZero(0.0)) return "it is all zeros";
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if (R.isZero(0.0)) return "its rotation block is all zeros";
  const double orthonormality = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (orthonormality > 1e-4)
    return "its rotation block is not orthonormal (|R^T R - I| = " + std::to_string(orthonormality) + ")";
  if (R.determinant() < 0) return "its rotation block is a reflection (determinant -1)";
  if (M.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) return "its last row is not 0 0 0 1";
  return "";
}

// Throws std::runtime_error naming the message (`which`, its utime) when its extrinsic is not rigid.
void CheckRigid(const ground_truth_t& truth, const std::string& which) {
  const std::string problem = RigidTransformProblem(truth.T_camera_lidar);
  if (!problem.empty())
    throw std::runtime_error("GROUND_TRUTH " + which + "from utime " + std::to_string(truth.utime) +
                             ": T_camera_lidar is not a rigid transform: " + problem);
}

bool IsResultFilePath(const std::string& path) {
  const auto ends_with = [&](const std::string& suffix) {
    return path.size() >= suffix.size() && path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with(".yaml") || ends_with(".yml");
}

}  // namespace

std::vector<ground_truth_t> ReadGroundTruths(const std::string& log_path) {
  LogReader reader(log_path);
  std::vector<ground_truth_t> truths;
  while (auto event = reader.Next()) {
    if (event->channel != channels::kGroundTruth.name) continue;
    ground_truth_t message{};
    if (message.decode(event->data.data(), 0, static_cast<int>(event->data.size())) >= 0)
      truths.push_back(std::move(message));
  }
  return truths;
}

std::optional<ground_truth_t> ReadGroundTruth(const std::string& log_path) {
  auto truths = ReadGroundTruths(log_path);
  if (truths.empty()) return std::nullopt;
  return std::move(truths.back());
}

std::optional<int> TruthStationAt(const ground_truth_t& truth, int64_t utime) {
  for (int k = 0; k < truth.num_stations; ++k)
    if (truth.still_from_utime[k] <= utime && utime <= truth.still_to_utime[k]) return k;
  return std::nullopt;
}

TruthExtrinsic CheckedTruthExtrinsic(const ground_truth_t& truth) {
  CheckRigid(truth, "");
  return {FromRowMajor(truth.T_camera_lidar), truth.utime};
}

TruthExtrinsic TruthExtrinsicAt(const std::vector<ground_truth_t>& truths, int64_t utime) {
  if (truths.empty()) throw std::runtime_error("no GROUND_TRUTH message");
  const ground_truth_t* in_force = nullptr;
  const ground_truth_t* earliest = &truths.front();
  for (size_t k = 0; k < truths.size(); ++k) {
    const ground_truth_t& t = truths[k];
    CheckRigid(t, "extrinsic " + std::to_string(k + 1) + " of " + std::to_string(truths.size()) + ", ");
    if (t.utime < earliest->utime) earliest = &t;
    if (t.utime <= utime && (!in_force || t.utime >= in_force->utime)) in_force = &t;
  }
  return CheckedTruthExtrinsic(in_force ? *in_force : *earliest);
}

TruthExtrinsic TruthExtrinsicAtEnd(const std::vector<ground_truth_t>& truths) {
  return TruthExtrinsicAt(truths, std::numeric_limits<int64_t>::max());
}

ReferenceExtrinsic ReadReference(const std::string& path, std::optional<int64_t> at_utime, const std::string& camera) {
  if (IsResultFilePath(path)) {
    if (at_utime)
      throw std::runtime_error(path +
                               ": a result file holds one extrinsic, with no time; choosing the "
                               "extrinsic in force at a utime needs a log with GROUND_TRUTH");
    if (camera.empty()) return {ReadResultFile(path).T_camera_lidar, std::nullopt};
    for (const auto& c : ReadRigFile(path).cameras)
      if (c.camera == camera) return {c.T_camera_lidar, std::nullopt};
    throw std::runtime_error(path + ": no camera " + camera);
  }
  std::vector<ground_truth_t> truths;
  for (auto& truth : ReadGroundTruths(path))
    if (truth.camera.name == camera) truths.push_back(std::move(truth));
  if (truths.empty())
    throw std::runtime_error(path + ": the log has no GROUND_TRUTH message" +
                             (camera.empty() ? std::string() : " of camera " + camera));
  try {
    const TruthExtrinsic e = at_utime ? TruthExtrinsicAt(truths, *at_utime) : TruthExtrinsicAtEnd(truths);
    return {e.T_camera_lidar, e.from_utime};
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

Isometry3 ReadReferenceExtrinsic(const std::string& path) { return ReadReference(path).T_camera_lidar; }

}  // namespace fusecal
