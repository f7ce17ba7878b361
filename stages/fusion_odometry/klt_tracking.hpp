// Step 3 of the fusion odometry (paper III-B-1, "the projected points are tracked into image j by KLT"):
// pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK) from image i into image j, starting at the pixel that
// the current motion estimate predicts (cv::OPTFLOW_USE_INITIAL_FLOW), so that large turns need no wide
// search; a track is kept when tracking it back from j lands next to where it started.
//
// Panoramas: the seam (longitude +-pi, the left and right image border) is no border of the scene, so both
// images are padded horizontally with wrapped-around columns (enough for the window at the coarsest pyramid
// level); tracking runs in the padded images and the tracked columns are wrapped back.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "stages/fusion_odometry/settings.hpp"

namespace fusecal::fusion_odometry {

class KltTracker {
 public:
  // grey_i, grey_j: 8-bit grey of the same size. wrap: columns wrap around (equirectangular).
  // border_px: tracks ending closer than this to the image border are lost (rows only when wrapping).
  // refine_window_px: the window of the full-resolution refinement (RefineWindowPx; 0: none).
  KltTracker(const cv::Mat& grey_i, const cv::Mat& grey_j, bool wrap, int border_px, const TrackingSettings& settings,
             int refine_window_px = 0);

  // Tracks pixels_i into image j, starting from predicted_j. pixels_j receives the tracked pixels (columns
  // in [-0.5, width - 0.5) when wrapping); ok[k] is false for a lost or inconsistent track.
  void Track(const std::vector<cv::Point2f>& pixels_i, const std::vector<cv::Point2f>& predicted_j,
             std::vector<cv::Point2f>* pixels_j, std::vector<unsigned char>* ok) const;

  int padding() const { return pad_; }

 private:
  // The second, full-resolution pass with refine_window_px_ (settings.hpp, refine_window_deg, says why).
  void RefineAtFullResolution(const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to) const;
  TrackingSettings settings_;
  bool wrap_;
  int border_px_, width_, height_, pad_ = 0;
  int refine_window_px_ = 0;
  std::vector<cv::Mat> pyramid_i_, pyramid_j_;
};

// The odd window of about settings.refine_window_deg at this pixel angle (radians per pixel, at the image
// centre), at least 5 px; 0 when that is not narrower than settings.window_px (no refinement).
int RefineWindowPx(const TrackingSettings& settings, double pixel_angle_rad);

}  // namespace fusecal::fusion_odometry
