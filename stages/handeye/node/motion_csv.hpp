// Motion pairs as CSV, for `fusecal handeye --motions FILE.csv`: a header line and the columns
//   a_qw,a_qx,a_qy,a_qz,a_tx,a_ty,a_tz,b_qw,b_qx,b_qy,b_qz,b_tx,b_ty,b_tz
// (A = camera motion T_ci_cj, B = LiDAR motion T_li_lj). Data row k (1-based) becomes the pair of
// stations (k-1, k).
#pragma once

#include <string>
#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

struct MotionCsv {
  std::vector<MotionPair> pairs;
  std::vector<std::string> problems;  // lines skipped, with the line number and the reason
};

// Throws std::runtime_error when the file cannot be read or the header is wrong; bad data lines are
// skipped and reported.
MotionCsv ReadMotionCsv(const std::string& path, bool camera_scaled);

}  // namespace fusecal
