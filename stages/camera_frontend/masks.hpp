// Where features may be detected (paper section III-A-1 works on panoramas from a Ladybug 3, whose images
// have stretched poles and may have unexposed areas).
#pragma once

#include <opencv2/core.hpp>

#include "stages/camera_frontend/settings.hpp"
#include "stages/foundation/camera_model.hpp"

namespace fusecal::camera_frontend {

// Blank areas: regions where the grey value equals blank_value over a whole 5x5 neighbourhood (a constant
// fill, not merely dark texture), grown by margin_px. Returns CV_8U, 255 where blank. All zero when
// blank_value < 0.
cv::Mat BlankAreas(const cv::Mat& grey, int blank_value, int margin_px);

// Rows of an equirectangular image whose |latitude| (row centre, camera_model.hpp convention) exceeds the
// limit. Returns CV_8U of the camera's size, 255 where masked out.
cv::Mat PoleRows(const CameraModel& camera, double max_abs_latitude_deg);

// Detection mask for a grey image of the camera's size: CV_8U, 255 where features may be detected (not
// blank, not near the poles of a panorama).
cv::Mat FeatureMask(const cv::Mat& grey, const CameraModel& camera, const FeatureSettings& settings);

}  // namespace fusecal::camera_frontend
