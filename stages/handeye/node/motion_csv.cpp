#include "stages/handeye/node/motion_csv.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace fusecal {

namespace {

const char* kHeader = "a_qw,a_qx,a_qy,a_qz,a_tx,a_ty,a_tz,b_qw,b_qx,b_qy,b_qz,b_tx,b_ty,b_tz";

std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
  size_t first = s.find_first_not_of(" \t");
  return first == std::string::npos ? "" : s.substr(first);
}

// Quaternion (w, x, y, z) and translation; false with *why when they are not a rigid motion.
bool ToIsometry(const double* v, Isometry3* T, std::string* why) {
  const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    std::ostringstream s;
    s << "quaternion is not unit (|q| = " << norm << ")";
    *why = s.str();
    return false;
  }
  *T = MakeIsometry(q.normalized().toRotationMatrix(), Eigen::Vector3d(v[4], v[5], v[6]));
  return true;
}

}  // namespace

MotionCsv ReadMotionCsv(const std::string& path, bool camera_scaled) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || Trim(line) != kHeader)
    throw std::runtime_error(path + ": line 1 must be the header " + std::string(kHeader));
  MotionCsv csv;
  int line_number = 1, row = 0;
  while (std::getline(in, line)) {
    ++line_number;
    line = Trim(line);
    if (line.empty()) continue;
    ++row;
    std::vector<double> values;
    std::stringstream fields(line);
    std::string field;
    bool parsed = true;
    while (std::getline(fields, field, ',')) {
      try {
        size_t used = 0;
        values.push_back(std::stod(Trim(field), &used));
        if (used != Trim(field).size()) parsed = false;
      } catch (const std::exception&) {
        parsed = false;
      }
    }
    const std::string where = path + ": line " + std::to_string(line_number) + ": ";
    if (!parsed || values.size() != 14) {
      csv.problems.push_back(where + "needs 14 numbers separated by commas (skipped)");
      continue;
    }
    bool finite = true;
    for (double v : values) finite = finite && std::isfinite(v);
    if (!finite) {
      csv.problems.push_back(where + "holds NaN or infinity (skipped)");
      continue;
    }
    MotionPair pair;
    pair.station_i = row - 1;
    pair.station_j = row;
    pair.camera_scaled = camera_scaled;
    std::string why;
    if (!ToIsometry(values.data(), &pair.A, &why) || !ToIsometry(values.data() + 7, &pair.B, &why)) {
      csv.problems.push_back(where + why + " (skipped)");
      continue;
    }
    csv.pairs.push_back(pair);
  }
  return csv;
}

}  // namespace fusecal
