#include "stages/camera_frontend/features.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "stages/camera_frontend/masks.hpp"

namespace fusecal {

namespace camera_frontend {

std::vector<int> SelectKeypointsByGrid(const std::vector<cv::KeyPoint>& keypoints, int width, int height,
                                       int max_features, int grid_cols, int grid_rows) {
  std::vector<int> order(keypoints.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return keypoints[a].response > keypoints[b].response; });
  if (static_cast<int>(order.size()) <= max_features) return order;

  const int cells = grid_cols * grid_rows;
  const int quota = std::max(1, max_features / cells);
  std::vector<int> taken_in_cell(cells, 0);
  std::vector<char> chosen(keypoints.size(), 0);
  std::vector<int> selected;
  selected.reserve(max_features);
  for (int k : order) {  // strongest first: each cell keeps its quota
    const cv::Point2f& p = keypoints[k].pt;
    const int cx = std::clamp(static_cast<int>((p.x + 0.5f) * grid_cols / width), 0, grid_cols - 1);
    const int cy = std::clamp(static_cast<int>((p.y + 0.5f) * grid_rows / height), 0, grid_rows - 1);
    int& taken = taken_in_cell[cy * grid_cols + cx];
    if (taken < quota && static_cast<int>(selected.size()) < max_features) {
      ++taken;
      chosen[k] = 1;
      selected.push_back(k);
    }
  }
  for (int k : order) {  // the budget left goes to the strongest of the rest
    if (static_cast<int>(selected.size()) >= max_features) break;
    if (!chosen[k]) selected.push_back(k);
  }
  std::stable_sort(selected.begin(), selected.end(),
                   [&](int a, int b) { return keypoints[a].response > keypoints[b].response; });
  return selected;
}

}  // namespace camera_frontend

std::string CheckImage(const cv::Mat& image, const CameraModel& camera) {
  if (image.empty()) return "image is empty";
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    return "unsupported image type (expected 8-bit grey, BGR or BGRA), got " + std::to_string(image.channels()) +
           " channel(s) of depth code " + std::to_string(image.depth());
  if (image.cols != camera.width() || image.rows != camera.height())
    return "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
           " but the camera model expects " + std::to_string(camera.width()) + "x" + std::to_string(camera.height());
  if (std::string e = TrackableSizeProblem(image.cols, image.rows); !e.empty()) return "image is " + e;
  return {};
}

namespace {

cv::Mat ToGrey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  return grey;
}

void Detect(const cv::Mat& grey, const cv::Mat& mask, const CameraModel& camera, const FeatureSettings& s,
            std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) {
  cv::Ptr<cv::AKAZE> akaze = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, static_cast<float>(s.akaze_threshold),
                                               s.akaze_octaves, s.akaze_octave_layers);
  const int pad = camera.WrapsHorizontally() ? std::min(s.seam_padding_px, grey.cols / 2) : 0;
  if (pad == 0) {
    akaze->detectAndCompute(grey, mask, *keypoints, *descriptors);
    return;
  }
  // Panorama: columns wrap around, so pad both sides with the opposite side's columns; features on the
  // seam then see their whole neighbourhood. Keypoints found inside the padding duplicate ones found in
  // the image itself and are dropped.
  cv::Mat grey_padded, mask_padded;
  cv::copyMakeBorder(grey, grey_padded, 0, 0, pad, pad, cv::BORDER_WRAP);
  cv::copyMakeBorder(mask, mask_padded, 0, 0, pad, pad, cv::BORDER_WRAP);
  std::vector<cv::KeyPoint> all;
  cv::Mat all_descriptors;
  akaze->detectAndCompute(grey_padded, mask_padded, all, all_descriptors);
  keypoints->clear();
  std::vector<int> keep;
  for (int k = 0; k < static_cast<int>(all.size()); ++k) {
    cv::KeyPoint kp = all[k];
    kp.pt.x -= static_cast<float>(pad);
    if (kp.pt.x < -0.5f || kp.pt.x >= grey.cols - 0.5f) continue;
    keypoints->push_back(kp);
    keep.push_back(k);
  }
  *descriptors = cv::Mat(static_cast<int>(keep.size()), all_descriptors.cols, all_descriptors.type());
  for (int r = 0; r < static_cast<int>(keep.size()); ++r) all_descriptors.row(keep[r]).copyTo(descriptors->row(r));
}

// Detect on the image scaled by settings.detection_scale, keypoints in pixels of the full image (pixel
// centres at integers: a scaled pixel centre u_s maps to (u_s + 0.5) / scale - 0.5).
void DetectScaled(const cv::Mat& grey, const cv::Mat& mask, const CameraModel& camera, const FeatureSettings& s,
                  std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) {
  const double scale = s.detection_scale;
  if (scale >= 1.0) return Detect(grey, mask, camera, s, keypoints, descriptors);
  const cv::Size size(std::max(1, static_cast<int>(std::lround(grey.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(grey.rows * scale))));
  cv::Mat grey_small, mask_small;
  cv::resize(grey, grey_small, size, 0, 0, cv::INTER_AREA);
  cv::resize(mask, mask_small, size, 0, 0, cv::INTER_NEAREST);
  FeatureSettings scaled = s;
  scaled.seam_padding_px = std::max(1, static_cast<int>(std::lround(s.seam_padding_px * scale)));
  Detect(grey_small, mask_small, camera, scaled, keypoints, descriptors);
  const double sx = static_cast<double>(grey.cols) / size.width, sy = static_cast<double>(grey.rows) / size.height;
  for (cv::KeyPoint& kp : *keypoints) {
    kp.pt.x = static_cast<float>((kp.pt.x + 0.5) * sx - 0.5);
    kp.pt.y = static_cast<float>((kp.pt.y + 0.5) * sy - 0.5);
    kp.size = static_cast<float>(kp.size * sx);
  }
}

}  // namespace

ImageFeatures ExtractImageFeatures(const cv::Mat& image, const CameraModel& camera, const FeatureSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  ImageFeatures out;
  out.width = image.cols;
  out.height = image.rows;
  auto finish = [&](Failure<FeatureFailure> failure) {
    out.failure_reason = std::move(failure);
    if (!out.usable()) {
      out.keypoints.clear();
      out.descriptors = cv::Mat();
      out.bearings.clear();
    }
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  };
  if (std::string e = settings.Validate(); !e.empty())
    return finish({FeatureFailure::kInvalidSettings, "invalid feature settings: " + e});
  if (std::string e = CheckImage(image, camera); !e.empty()) return finish({FeatureFailure::kBadImage, e});
  try {
    const cv::Mat grey = ToGrey(image);
    const cv::Mat mask = camera_frontend::FeatureMask(grey, camera, settings);
    if (cv::countNonZero(mask) == 0)
      return finish({FeatureFailure::kNoFeatures, "no features: the whole image is blank or masked"});

    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    DetectScaled(grey, mask, camera, settings, &keypoints, &descriptors);
    out.detected = static_cast<int>(keypoints.size());
    if (keypoints.empty())
      return finish({FeatureFailure::kNoFeatures, "no features: AKAZE found no keypoint (blank or textureless image)"});

    const std::vector<int> selected = camera_frontend::SelectKeypointsByGrid(
        keypoints, image.cols, image.rows, settings.max_features, settings.grid_cols, settings.grid_rows);
    out.keypoints.reserve(selected.size());
    out.bearings.reserve(selected.size());
    out.descriptors = cv::Mat(static_cast<int>(selected.size()), descriptors.cols, descriptors.type());
    for (int r = 0; r < static_cast<int>(selected.size()); ++r) {
      const cv::KeyPoint& kp = keypoints[selected[r]];
      out.keypoints.push_back(kp);
      descriptors.row(selected[r]).copyTo(out.descriptors.row(r));
      out.bearings.push_back(camera.Unproject(Eigen::Vector2d(kp.pt.x, kp.pt.y)).normalized());
    }
    return finish({});
  } catch (const std::exception& e) {
    return finish({FeatureFailure::kInternalError, std::string("feature extraction failed: ") + e.what()});
  }
}

}  // namespace fusecal
