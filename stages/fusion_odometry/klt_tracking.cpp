#include "stages/fusion_odometry/klt_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace fusecal::fusion_odometry {

KltTracker::KltTracker(const cv::Mat& grey_i, const cv::Mat& grey_j, bool wrap, int border_px,
                       const TrackingSettings& settings, int refine_window_px)
    : settings_(settings),
      wrap_(wrap),
      border_px_(border_px),
      width_(grey_i.cols),
      height_(grey_i.rows),
      refine_window_px_(refine_window_px) {
  const cv::Size window(settings.window_px, settings.window_px);
  cv::Mat image_i = grey_i, image_j = grey_j;
  if (wrap_) {
    // The window at level L covers window_px * 2^L pixels of the full image.
    pad_ = std::min((settings.window_px / 2 + 2) << settings.pyramid_levels, width_);
    cv::copyMakeBorder(grey_i, image_i, 0, 0, pad_, pad_, cv::BORDER_WRAP);
    cv::copyMakeBorder(grey_j, image_j, 0, 0, pad_, pad_, cv::BORDER_WRAP);
  }
  cv::buildOpticalFlowPyramid(image_i, pyramid_i_, window, settings.pyramid_levels);
  cv::buildOpticalFlowPyramid(image_j, pyramid_j_, window, settings.pyramid_levels);
}

void KltTracker::Track(const std::vector<cv::Point2f>& pixels_i, const std::vector<cv::Point2f>& predicted_j,
                       std::vector<cv::Point2f>* pixels_j, std::vector<unsigned char>* ok) const {
  const size_t n = pixels_i.size();
  pixels_j->assign(n, cv::Point2f(0, 0));
  ok->assign(n, 0);
  if (n == 0 || predicted_j.size() != n) return;

  const cv::Point2f shift(static_cast<float>(pad_), 0.0f);
  std::vector<cv::Point2f> from(n), to(n), back(n);
  for (size_t k = 0; k < n; ++k) {
    from[k] = pixels_i[k] + shift;
    to[k] = predicted_j[k] + shift;
  }
  const cv::Size window(settings_.window_px, settings_.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, settings_.max_iterations,
                                  settings_.epsilon_px);
  std::vector<unsigned char> status_forward, status_backward;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(pyramid_i_, pyramid_j_, from, to, status_forward, error, window, settings_.pyramid_levels,
                           criteria, cv::OPTFLOW_USE_INITIAL_FLOW, settings_.min_eigen_threshold);
  RefineAtFullResolution(from, &to);
  // Forward-backward check: track j back into i, starting at the original pixel.
  back = from;
  cv::calcOpticalFlowPyrLK(pyramid_j_, pyramid_i_, to, back, status_backward, error, window, settings_.pyramid_levels,
                           criteria, cv::OPTFLOW_USE_INITIAL_FLOW, settings_.min_eigen_threshold);

  const double max_fb2 = settings_.max_forward_backward_px * settings_.max_forward_backward_px;
  const float x_lo = wrap_ ? -1e9f : static_cast<float>(border_px_);
  const float x_hi = wrap_ ? 1e9f : static_cast<float>(width_ - 1 - border_px_);
  const float y_lo = static_cast<float>(border_px_), y_hi = static_cast<float>(height_ - 1 - border_px_);
  for (size_t k = 0; k < n; ++k) {
    if (!status_forward[k] || !status_backward[k]) continue;
    const cv::Point2f d = back[k] - from[k];
    if (!(d.dot(d) <= max_fb2)) continue;
    cv::Point2f p = to[k] - shift;
    if (wrap_) {  // back into [-0.5, width - 0.5)
      p.x = static_cast<float>(std::fmod(p.x + 0.5, static_cast<double>(width_)));
      if (p.x < 0) p.x += static_cast<float>(width_);
      p.x -= 0.5f;
    }
    if (!(p.x >= x_lo && p.x <= x_hi && p.y >= y_lo && p.y <= y_hi)) continue;
    (*pixels_j)[k] = p;
    (*ok)[k] = 1;
  }
}

void KltTracker::RefineAtFullResolution(const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to) const {
  if (refine_window_px_ <= 0 || from.empty()) return;
  const cv::Size window(refine_window_px_, refine_window_px_);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, settings_.max_iterations,
                                  settings_.epsilon_px);
  std::vector<cv::Point2f> refined = *to;
  std::vector<unsigned char> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(pyramid_i_, pyramid_j_, from, refined, status, error, window, 0, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW, settings_.min_eigen_threshold);
  // Where the small window cannot track (too little texture in it), or wanders off (more than a pixel:
  // it locked onto something else), the wide window's track stands.
  for (size_t k = 0; k < from.size(); ++k) {
    const cv::Point2f moved = refined[k] - (*to)[k];
    if (status[k] && moved.dot(moved) <= 1.0f) (*to)[k] = refined[k];
  }
}

int RefineWindowPx(const TrackingSettings& settings, double pixel_angle_rad) {
  if (settings.refine_window_deg <= 0 || !(pixel_angle_rad > 0)) return 0;
  const double pixels = settings.refine_window_deg * M_PI / 180.0 / pixel_angle_rad;
  const int odd = std::max(5, 2 * static_cast<int>(std::lround((pixels - 1.0) / 2.0)) + 1);
  return odd < settings.window_px ? odd : 0;
}

}  // namespace fusecal::fusion_odometry
