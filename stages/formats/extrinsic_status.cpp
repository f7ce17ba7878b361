#include "stages/formats/extrinsic_status.hpp"

#include <algorithm>

namespace fusecal {

const char* ExtrinsicStatusName(int8_t status) {
  if (status == extrinsic_t::STATUS_INITIAL) return "initial";
  if (status == extrinsic_t::STATUS_REFINING) return "refining";
  const std::optional<HandEyeStatus> verdict = HandEyeStatusOf(status);
  return verdict ? Name(*verdict) : "unknown";
}

const char* ObservabilityName(int8_t observability) {
  const std::optional<Observability> verdict = ObservabilityOf(observability);
  return verdict ? Name(*verdict) : "unknown";
}

int8_t ToExtrinsicStatus(HandEyeStatus status) {
  switch (status) {
    case HandEyeStatus::kConverged:
      return extrinsic_t::STATUS_CONVERGED;
    case HandEyeStatus::kNotConverged:
      return extrinsic_t::STATUS_NOT_CONVERGED;
    case HandEyeStatus::kDegenerate:
      return extrinsic_t::STATUS_DEGENERATE;
    case HandEyeStatus::kFailed:
      return extrinsic_t::STATUS_FAILED;
  }
  return extrinsic_t::STATUS_FAILED;
}

int8_t ToExtrinsicObservability(Observability observability) {
  switch (observability) {
    case Observability::kOk:
      return extrinsic_t::OBSERVABILITY_OK;
    case Observability::kRotationDegenerate:
      return extrinsic_t::OBSERVABILITY_ROTATION_DEGENERATE;
    case Observability::kTranslationPartlyUnobservable:
      return extrinsic_t::OBSERVABILITY_TRANSLATION_PARTLY_UNOBSERVABLE;
    case Observability::kTooFewMotions:
      return extrinsic_t::OBSERVABILITY_TOO_FEW_MOTIONS;
  }
  return extrinsic_t::OBSERVABILITY_TOO_FEW_MOTIONS;
}

std::optional<HandEyeStatus> HandEyeStatusOf(int8_t status) {
  switch (status) {
    case extrinsic_t::STATUS_CONVERGED:
      return HandEyeStatus::kConverged;
    case extrinsic_t::STATUS_NOT_CONVERGED:
      return HandEyeStatus::kNotConverged;
    case extrinsic_t::STATUS_DEGENERATE:
      return HandEyeStatus::kDegenerate;
    case extrinsic_t::STATUS_FAILED:
      return HandEyeStatus::kFailed;
    default:
      return std::nullopt;
  }
}

std::optional<Observability> ObservabilityOf(int8_t observability) {
  switch (observability) {
    case extrinsic_t::OBSERVABILITY_OK:
      return Observability::kOk;
    case extrinsic_t::OBSERVABILITY_ROTATION_DEGENERATE:
      return Observability::kRotationDegenerate;
    case extrinsic_t::OBSERVABILITY_TRANSLATION_PARTLY_UNOBSERVABLE:
      return Observability::kTranslationPartlyUnobservable;
    case extrinsic_t::OBSERVABILITY_TOO_FEW_MOTIONS:
      return Observability::kTooFewMotions;
    default:
      return std::nullopt;
  }
}

bool UsesMotionTo(const extrinsic_t& e, int station_j) {
  return std::find(e.used_station_j.begin(), e.used_station_j.end(), station_j) != e.used_station_j.end();
}

bool TookMotionTo(const extrinsic_t& e, int station_j) {
  return UsesMotionTo(e, station_j) ||
         std::find(e.rejected_station_j.begin(), e.rejected_station_j.end(), station_j) != e.rejected_station_j.end();
}

}  // namespace fusecal
