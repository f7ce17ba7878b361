// Hand-eye results into the common result file and into EXTRINSIC messages.
#pragma once

#include "fusecal/extrinsic_t.hpp"
#include "stages/formats/result_file.hpp"
#include "stages/handeye/handeye_solver.hpp"

namespace fusecal {

// `name_pair(i, j)` names a motion in motions_used / motions_rejected (e.g. "3-4" or "row 5").
CalibrationResult ToCalibrationResult(const HandEyeResult& result,
                                      const std::function<std::string(int, int)>& name_pair);

extrinsic_t ToExtrinsicMessage(const HandEyeResult& result, int version, int64_t utime);

}  // namespace fusecal
