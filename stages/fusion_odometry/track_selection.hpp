// Step 2 of the fusion odometry: which visible scan points to track. KLT needs texture in its window, so
// only points at trackable places are kept (Shi and Tomasi, "Good Features to Track", CVPR 1994: the
// smaller eigenvalue of the gradient structure tensor at the projected pixel), away from depth edges (the
// window would mix a foreground and a background motion), spread out by a minimum spacing, strongest
// first, within a budget.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "stages/foundation/camera_model.hpp"
#include "stages/fusion_odometry/settings.hpp"
#include "stages/fusion_odometry/types.hpp"
#include "stages/fusion_odometry/visibility.hpp"

namespace fusecal::fusion_odometry {

// Shi-Tomasi response (cv::cornerMinEigenVal, float) of an 8-bit grey image; columns wrap for panoramas.
cv::Mat CornerResponse(const cv::Mat& grey, int block_size, bool wrap);

// Selects from visible.points. border_px: no point closer than this to the image border (columns of a
// panorama wrap and have no border).
std::vector<ScanPoint> SelectTrackable(const VisibleScan& visible, const cv::Mat& response, const CameraModel& camera,
                                       int border_px, const SelectionSettings& settings);

}  // namespace fusecal::fusion_odometry
