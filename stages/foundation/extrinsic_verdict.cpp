#include "stages/foundation/extrinsic_verdict.hpp"

namespace fusecal {

const char* Name(HandEyeStatus status) {
  switch (status) {
    case HandEyeStatus::kConverged:
      return "converged";
    case HandEyeStatus::kNotConverged:
      return "not_converged";
    case HandEyeStatus::kDegenerate:
      return "degenerate";
    case HandEyeStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

const char* Name(Observability observability) {
  switch (observability) {
    case Observability::kOk:
      return "ok";
    case Observability::kRotationDegenerate:
      return "rotation_degenerate";
    case Observability::kTranslationPartlyUnobservable:
      return "translation_partly_unobservable";
    case Observability::kTooFewMotions:
      return "too_few_motions";
  }
  return "unknown";
}

}  // namespace fusecal
