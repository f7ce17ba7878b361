// Image motion between two frames: median displacement of KLT-tracked Shi-Tomasi corners on downscaled,
// photometrically normalised grey images. The median makes it robust to objects moving in front of a
// still rig; the normalisation (zero mean, fixed standard deviation) to exposure changes and flicker.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "stages/foundation/stage_result.hpp"
#include "stages/stationarity/settings.hpp"

namespace fusecal {

// An image prepared once for tracking from and to.
struct ImageFrame {
  int64_t utime = 0;
  cv::Mat grey;                      // working resolution, normalised; empty when not textured
  std::vector<cv::Point2f> corners;  // Shi-Tomasi corners in `grey`
  std::vector<cv::Mat> pyramid;      // KLT pyramid of `grey` (cv::buildOpticalFlowPyramid), built once
  double px_scale = 1.0;             // working pixels -> pixels of an image working_width_px wide
  double contrast = 0.0;             // standard deviation of the working grey values before normalising
  bool textured = false;             // contrast >= min_contrast and enough corners
};

// True when `image` is a non-empty 8-bit image with 1, 3 (BGR) or 4 (BGRA) channels.
bool IsSupportedImage(const cv::Mat& image);

// Grey, downscale (cv::INTER_AREA), normalise, detect corners. `image` must be supported.
ImageFrame PrepareImage(int64_t utime, const cv::Mat& image, const ImageMotionSettings& settings);

// Why an image flow cannot decide.
enum class ImageFlowFailure {
  kNone,          // usable: enough tracks to decide
  kNotRun,        // a default-constructed result
  kNoTexture,     // a frame without texture
  kSizeChanged,   // the frames' working sizes differ
  kTrackingLost,  // too few tracks survived
  kNotMeasured,   // the detector skipped the measurement (the drift while the rig moves)
};

struct ImageFlow {
  bool usable() const { return failure_reason.code == ImageFlowFailure::kNone; }
  double median_px = 0;  // median displacement, pixels of an image working_width_px wide
  int corners = 0;       // corners tracked from
  int tracks = 0;        // tracks that passed the forward-backward check
  Failure<ImageFlowFailure> failure_reason{ImageFlowFailure::kNotRun, {}};
};

// Tracks the corners of `from` into `to` and back. Not usable when either frame is not textured, their
// working sizes differ, or too few tracks survive (large motion, occlusion, a different scene).
ImageFlow MeasureFlow(const ImageFrame& from, const ImageFrame& to, const ImageMotionSettings& settings);

}  // namespace fusecal
