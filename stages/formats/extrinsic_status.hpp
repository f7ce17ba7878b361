// extrinsic_t's STATUS_* and OBSERVABILITY_* constants: their names, as the result file (extrinsic.yaml),
// the JSON of `fusecal log dump` and the progress lines write them, and their conversion from and to the
// hand-eye verdict (foundation/extrinsic_verdict.hpp), whose Name() they share.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "fusecal/extrinsic_t.hpp"
#include "stages/foundation/extrinsic_verdict.hpp"

namespace fusecal {

// "initial", "refining", "converged", "not_converged", "degenerate", "failed"; "unknown" otherwise.
const char* ExtrinsicStatusName(int8_t status);
// "ok", "rotation_degenerate", "translation_partly_unobservable", "too_few_motions"; "unknown" otherwise.
const char* ObservabilityName(int8_t observability);

// The constant of a hand-eye status or observability.
int8_t ToExtrinsicStatus(HandEyeStatus status);
int8_t ToExtrinsicObservability(Observability observability);
// The hand-eye status of a constant; none for INITIAL, REFINING (the alternation's own) and unknown values.
std::optional<HandEyeStatus> HandEyeStatusOf(int8_t status);
// The observability of a constant; none for unknown values.
std::optional<Observability> ObservabilityOf(int8_t observability);

// A version with status INITIAL or REFINING belongs to a round of the alternation that has not ended
// (INITIAL, the scaleless record, is always followed by REFINING).
inline bool RoundRunning(const extrinsic_t& e) {
  return e.status == extrinsic_t::STATUS_REFINING || e.status == extrinsic_t::STATUS_INITIAL;
}

// Whether version `e` used a motion ending at station j; and whether it used or rejected one (the
// pipeline has dealt with that station's motion).
bool UsesMotionTo(const extrinsic_t& e, int station_j);
bool TookMotionTo(const extrinsic_t& e, int station_j);

}  // namespace fusecal
