// What an estimate of the extrinsic is worth: the status and the observability verdict of the hand-eye
// solver. The hand-eye core produces them; the message and file formats carry them as extrinsic_t's
// STATUS_* / OBSERVABILITY_* constants and as the names below.
#pragma once

namespace fusecal {

enum class HandEyeStatus {
  kConverged,     // observable, solver converged
  kNotConverged,  // observable, iteration limit reached
  kDegenerate,    // best estimate, but see observability
  kFailed,        // no estimate (bad settings, < 2 pairs)
};

enum class Observability {
  kOk,
  // Rotation about one axis is not determined. Direction: that axis in the camera frame. With scaled motions
  // this happens when all motions rotate about one common line (e.g. panning on a tripod); translation along
  // the axis is then unobservable too. With scaleless motions, whenever all rotation axes are parallel.
  kRotationDegenerate,
  // Rotation is determined, t is not along the unobservable direction (camera frame). Scaled motions about
  // one axis only (planar motion): t along the axis. Scaleless: e.g. few planar motions.
  kTranslationPartlyUnobservable,
  // Fewer usable pairs than the solver's min_pairs.
  kTooFewMotions,
};

// The names result files, JSON and progress lines use: "converged", "not_converged", "degenerate",
// "failed".
const char* Name(HandEyeStatus status);
// "ok", "rotation_degenerate", "translation_partly_unobservable", "too_few_motions".
const char* Name(Observability observability);

}  // namespace fusecal
