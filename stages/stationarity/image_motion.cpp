#include "stages/stationarity/image_motion.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace fusecal {

namespace {

constexpr double kNormalisedMean = 128.0, kNormalisedStd = 48.0;

double Median(std::vector<float> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + mid));
  return m;
}

// The strongest Shi-Tomasi corner of each cell of a grid of about max_corners cells.
std::vector<cv::Point2f> GridCorners(const cv::Mat& grey, const ImageMotionSettings& settings) {
  cv::Mat eig;
  cv::cornerMinEigenVal(grey, eig, 3, 3);
  double strongest = 0;
  cv::minMaxLoc(eig, nullptr, &strongest);
  const double threshold = settings.corner_quality * strongest;
  const int border = 3;  // the 3x3 block and Sobel see past the edge there
  const int w = grey.cols - 2 * border, h = grey.rows - 2 * border;
  std::vector<cv::Point2f> corners;
  if (w < 4 || h < 4 || !(strongest > 0)) return corners;
  const int cols = std::clamp(static_cast<int>(std::lround(std::sqrt(settings.max_corners * double(w) / h))), 1,
                              settings.max_corners);
  const int rows = std::max(1, settings.max_corners / cols);
  corners.reserve(static_cast<size_t>(rows) * cols);
  for (int r = 0; r < rows; ++r) {
    const int y0 = border + r * h / rows, y1 = border + (r + 1) * h / rows;
    for (int c = 0; c < cols; ++c) {
      const int x0 = border + c * w / cols, x1 = border + (c + 1) * w / cols;
      if (x1 <= x0 || y1 <= y0) continue;
      double value = 0;
      cv::Point at;
      cv::minMaxLoc(eig(cv::Rect(x0, y0, x1 - x0, y1 - y0)), nullptr, &value, nullptr, &at);
      if (value > 0 && value >= threshold)
        corners.emplace_back(static_cast<float>(x0 + at.x), static_cast<float>(y0 + at.y));
    }
  }
  return corners;
}

}  // namespace

bool IsSupportedImage(const cv::Mat& image) {
  return !image.empty() && image.depth() == CV_8U && image.dims == 2 &&
         (image.channels() == 1 || image.channels() == 3 || image.channels() == 4);
}

ImageFrame PrepareImage(int64_t utime, const cv::Mat& image, const ImageMotionSettings& settings) {
  ImageFrame f;
  f.utime = utime;
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4)
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  else
    grey = image;

  cv::Mat small;
  if (grey.cols > settings.working_width_px) {
    const double s = static_cast<double>(settings.working_width_px) / grey.cols;
    const int rows = std::max(1, static_cast<int>(std::lround(grey.rows * s)));
    cv::resize(grey, small, cv::Size(settings.working_width_px, rows), 0, 0, cv::INTER_AREA);
  } else {
    small = grey;
  }
  f.px_scale = static_cast<double>(settings.working_width_px) / small.cols;

  cv::Scalar mean, stddev;
  cv::meanStdDev(small, mean, stddev);
  f.contrast = stddev[0];
  if (!(f.contrast >= settings.min_contrast) || f.contrast <= 0) return f;

  // Photometric normalisation: a global gain or offset change (exposure, flicker) leaves it unchanged.
  const double alpha = kNormalisedStd / f.contrast;
  small.convertTo(f.grey, CV_8U, alpha, kNormalisedMean - alpha * mean[0]);

  f.corners = GridCorners(f.grey, settings);
  f.textured = static_cast<int>(f.corners.size()) >= settings.min_tracks;
  if (!f.textured) {
    f.grey.release();
    return f;
  }
  // The pyramid (with derivatives) serves every track from and to this frame.
  cv::buildOpticalFlowPyramid(f.grey, f.pyramid, cv::Size(settings.klt_window_px, settings.klt_window_px),
                              settings.klt_pyramid_levels);
  return f;
}

ImageFlow MeasureFlow(const ImageFrame& from, const ImageFrame& to, const ImageMotionSettings& settings) {
  ImageFlow out;
  out.corners = static_cast<int>(from.corners.size());
  if (!from.textured || !to.textured) {
    out.failure_reason = {ImageFlowFailure::kNoTexture, "no texture to track"};
    return out;
  }
  if (from.grey.size() != to.grey.size()) {
    out.failure_reason = {ImageFlowFailure::kSizeChanged, "image size changed"};
    return out;
  }
  const cv::Size window(settings.klt_window_px, settings.klt_window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Point2f> forward, backward;
  std::vector<uchar> status_f, status_b;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(from.pyramid, to.pyramid, from.corners, forward, status_f, err, window,
                           settings.klt_pyramid_levels, term);
  cv::calcOpticalFlowPyrLK(to.pyramid, from.pyramid, forward, backward, status_b, err, window,
                           settings.klt_pyramid_levels, term);
  std::vector<float> displacement;
  displacement.reserve(from.corners.size());
  const float max_fb2 = static_cast<float>(settings.max_forward_backward_px * settings.max_forward_backward_px);
  for (size_t i = 0; i < from.corners.size(); ++i) {
    if (!status_f[i] || !status_b[i]) continue;
    const cv::Point2f fb = backward[i] - from.corners[i];
    if (fb.dot(fb) > max_fb2) continue;
    const cv::Point2f d = forward[i] - from.corners[i];
    displacement.push_back(std::sqrt(d.dot(d)));
  }
  out.tracks = static_cast<int>(displacement.size());
  const int needed =
      std::max(settings.min_tracks, static_cast<int>(std::ceil(settings.min_tracked_fraction * out.corners)));
  if (out.tracks < needed) {
    out.failure_reason = {ImageFlowFailure::kTrackingLost, "tracking lost (" + std::to_string(out.tracks) + " of " +
                                                               std::to_string(out.corners) + " corners tracked)"};
    return out;
  }
  out.median_px = Median(std::move(displacement)) * from.px_scale;
  out.failure_reason = {};
  return out;
}

}  // namespace fusecal
