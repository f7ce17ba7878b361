#include "stages/fusion_odometry/track_selection.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>

namespace fusecal::fusion_odometry {

cv::Mat CornerResponse(const cv::Mat& grey, int block_size, bool wrap) {
  cv::Mat response;
  if (!wrap) {
    cv::cornerMinEigenVal(grey, response, block_size, 3);
    return response;
  }
  const int pad = std::min(block_size + 2, grey.cols);
  cv::Mat padded;
  cv::copyMakeBorder(grey, padded, 0, 0, pad, pad, cv::BORDER_WRAP);
  cv::cornerMinEigenVal(padded, response, block_size, 3);
  return response.colRange(pad, pad + grey.cols).clone();
}

namespace {

// Occupancy grid enforcing a minimum distance between kept pixels (columns wrap for panoramas).
class SpacingGrid {
 public:
  SpacingGrid(int width, int height, double min_distance, bool wrap)
      : cell_(std::max(1.0, min_distance)),
        min_distance2_(min_distance * min_distance),
        width_(width),
        cols_(static_cast<int>(std::ceil((width + 1) / cell_))),
        rows_(static_cast<int>(std::ceil((height + 1) / cell_))),
        wrap_(wrap),
        cells_(static_cast<size_t>(cols_) * rows_) {}

  bool Free(const Eigen::Vector2d& pixel) const {
    if (min_distance2_ <= 0) return true;
    const int c = Col(pixel.x()), r = Row(pixel.y());
    for (int dr = -1; dr <= 1; ++dr) {
      const int rr = r + dr;
      if (rr < 0 || rr >= rows_) continue;
      for (int dc = -1; dc <= 1; ++dc) {
        int cc = c + dc;
        if (wrap_) cc = (cc + cols_) % cols_;
        if (cc < 0 || cc >= cols_) continue;
        for (const Eigen::Vector2d& q : cells_[static_cast<size_t>(rr) * cols_ + cc]) {
          double dx = std::abs(q.x() - pixel.x());
          if (wrap_) dx = std::min(dx, width_ - dx);
          const double dy = q.y() - pixel.y();
          if (dx * dx + dy * dy < min_distance2_) return false;
        }
      }
    }
    return true;
  }

  void Add(const Eigen::Vector2d& pixel) {
    cells_[static_cast<size_t>(Row(pixel.y())) * cols_ + Col(pixel.x())].push_back(pixel);
  }

 private:
  int Col(double u) const { return std::clamp(static_cast<int>((u + 0.5) / cell_), 0, cols_ - 1); }
  int Row(double v) const { return std::clamp(static_cast<int>((v + 0.5) / cell_), 0, rows_ - 1); }

  double cell_, min_distance2_, width_;
  int cols_, rows_;
  bool wrap_;
  std::vector<std::vector<Eigen::Vector2d>> cells_;
};

}  // namespace

std::vector<ScanPoint> SelectTrackable(const VisibleScan& visible, const cv::Mat& response, const CameraModel& camera,
                                       int border_px, const SelectionSettings& settings) {
  const bool wrap = camera.WrapsHorizontally();
  const int w = camera.width(), h = camera.height();
  const double max_abs_lat = settings.max_abs_latitude_deg * M_PI / 180.0;

  // Candidates: inside the border, off depth edges, with their corner response.
  std::vector<int> candidates;
  std::vector<float> score(visible.points.size(), 0.0f);
  float strongest = 0.0f;
  for (size_t k = 0; k < visible.points.size(); ++k) {
    const ScanPoint& s = visible.points[k];
    const int u = static_cast<int>(std::lround(s.pixel_i.x())), v = static_cast<int>(std::lround(s.pixel_i.y()));
    if (v < border_px || v >= h - border_px) continue;
    if (wrap) {
      const Eigen::Vector3d f = s.p_ci / s.range;
      if (std::abs(std::asin(std::clamp(-f.y(), -1.0, 1.0))) > max_abs_lat) continue;
    } else if (u < border_px || u >= w - border_px) {
      continue;
    }
    if (settings.depth_edge_radius_px > 0 &&
        visible.grid.SecondDifference(s.pixel_i, s.range, settings.depth_edge_radius_px).most_positive >
            settings.depth_edge_tolerance * s.range)
      continue;
    score[k] = response.at<float>(std::clamp(v, 0, h - 1), (u % w + w) % w);
    strongest = std::max(strongest, score[k]);
    candidates.push_back(static_cast<int>(k));
  }
  const float threshold = static_cast<float>(settings.min_corner_quality) * strongest;
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(), [&](int k) { return !(score[k] > threshold); }),
                   candidates.end());
  // Strongest first; ties by scan index so the result does not depend on the sort implementation.
  std::sort(candidates.begin(), candidates.end(),
            [&](int a, int b) { return score[a] != score[b] ? score[a] > score[b] : a < b; });

  std::vector<ScanPoint> selected;
  SpacingGrid spacing(w, h, settings.min_distance_px, wrap);
  for (int k : candidates) {
    if (static_cast<int>(selected.size()) >= settings.max_points) break;
    const ScanPoint& s = visible.points[k];
    if (!spacing.Free(s.pixel_i)) continue;
    spacing.Add(s.pixel_i);
    selected.push_back(s);
  }
  return selected;
}

}  // namespace fusecal::fusion_odometry
