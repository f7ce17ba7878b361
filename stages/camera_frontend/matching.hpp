// Descriptor matching (paper section III-A-1: features are matched between the two images).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "stages/camera_frontend/settings.hpp"

namespace fusecal::camera_frontend {

// Brute-force Hamming matching of binary descriptors (CV_8U rows of equal length): for each row of
// descriptors_i its two nearest rows of descriptors_j; kept when nearest < ratio * second nearest (Lowe's
// ratio test) and, with mutual_check, when that row of descriptors_j has the row of descriptors_i as its
// own nearest. DMatch::queryIdx indexes image i, trainIdx image j, distance is the Hamming distance.
//
// Same result as cv::BFMatcher(NORM_HAMMING) knnMatch(k = 2) + match() the other way round, but one pass
// over all pairs and hardware popcount where the CPU has it (Debian's OpenCV is built for a baseline
// without it, which made BFMatcher the slowest step: ~0.3 s for 2500 x 2500 descriptors).
// Ties are broken towards the lower index.
std::vector<cv::DMatch> MatchDescriptors(const cv::Mat& descriptors_i, const cv::Mat& descriptors_j,
                                         const MatchingSettings& settings);

}  // namespace fusecal::camera_frontend
