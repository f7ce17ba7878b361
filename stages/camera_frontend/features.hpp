// AKAZE features with a budget (paper section III-A-1: "AKAZE features are extracted from both images").
//
// Features of one image are independent of the other image of a pair, so a caller that estimates the
// motions i->j and j->k extracts the features of image j once and passes them to EstimateRelativePose.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "stages/camera_frontend/settings.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/stage_result.hpp"

namespace fusecal {

// Why the features of an image are not usable.
enum class FeatureFailure {
  kNone,             // usable (also a default-constructed, empty set)
  kInvalidSettings,  // settings.Validate() failed
  kBadImage,         // empty, of an unsupported type, or not the camera's size
  kNoFeatures,       // blank or masked image, or AKAZE found no keypoint
  kInternalError,    // an exception inside the extraction
};

struct ImageFeatures {
  int width = 0;  // size of the image they come from
  int height = 0;
  std::vector<cv::KeyPoint> keypoints;     // pixel convention of camera_model.hpp
  cv::Mat descriptors;                     // CV_8U, one binary (MLDB) descriptor per row
  std::vector<Eigen::Vector3d> bearings;   // unit bearing of each keypoint, camera frame
  int detected = 0;                        // keypoints AKAZE found in the mask, before the budget
  Failure<FeatureFailure> failure_reason;  // when not usable the vectors are empty
  double seconds = 0.0;

  bool usable() const { return failure_reason.code == FeatureFailure::kNone; }
};

// Checks the image against the camera (size, type): empty string when usable, else why not.
std::string CheckImage(const cv::Mat& image, const CameraModel& camera);

// Detects AKAZE features in an 8-bit grey, BGR or BGRA image of the camera's size (masks.hpp: no features
// in blank areas and near the poles of a panorama; the seam of a panorama is padded by wrap-around), keeps
// the budget spread over a grid and unprojects them. Never throws: problems go to failure_reason.
ImageFeatures ExtractImageFeatures(const cv::Mat& image, const CameraModel& camera,
                                   const FeatureSettings& settings = {});

namespace camera_frontend {

// Indices of at most max_features keypoints: each of the grid_cols x grid_rows cells over a
// width x height image keeps its strongest max_features / cells, the budget left goes to the strongest
// of the rest. Sorted by decreasing response.
std::vector<int> SelectKeypointsByGrid(const std::vector<cv::KeyPoint>& keypoints, int width, int height,
                                       int max_features, int grid_cols, int grid_rows);

}  // namespace camera_frontend
}  // namespace fusecal
