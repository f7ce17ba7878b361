#include "overlay.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace fusecal {

ProjectedScan ProjectScan(const PointCloud& cloud, const CameraModel& camera, const Isometry3& T_camera_lidar) {
  ProjectedScan out{cv::Mat::zeros(camera.height(), camera.width(), CV_32F),
                    cv::Mat::zeros(camera.height(), camera.width(), CV_32F)};
  const Eigen::Matrix3d R = T_camera_lidar.linear();
  const Eigen::Vector3d t = T_camera_lidar.translation();
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) continue;
    const Eigen::Vector3d p = R * cloud.points[i].cast<double>() + t;
    Eigen::Vector2d px;
    if (!camera.Project(p, &px)) continue;
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= camera.width() || v >= camera.height()) continue;
    const float depth = static_cast<float>(p.norm());
    float& d = out.depth.at<float>(v, u);
    if (d == 0 || depth < d) {
      d = depth;
      out.intensity.at<float>(v, u) = cloud.HasIntensity() ? cloud.intensity[i] : 1.0f;
    }
  }
  return out;
}

namespace {

cv::Mat ToBgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1)
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else
    bgr = image.clone();
  return bgr;
}

}  // namespace

cv::Mat RenderDepthOverlay(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                           const Isometry3& T_camera_lidar, double max_depth_m) {
  cv::Mat canvas = ToBgr(image);
  const ProjectedScan scan = ProjectScan(cloud, camera, T_camera_lidar);
  // Colour scale from the scene itself (95th percentile of the depths), capped at max_depth_m.
  std::vector<float> depths;
  for (int v = 0; v < scan.depth.rows; ++v)
    for (int u = 0; u < scan.depth.cols; ++u)
      if (scan.depth.at<float>(v, u) > 0) depths.push_back(scan.depth.at<float>(v, u));
  if (depths.empty()) return canvas;
  std::nth_element(depths.begin(), depths.begin() + depths.size() * 95 / 100, depths.end());
  const double scale_max = std::min<double>(max_depth_m, std::max(1.0f, depths[depths.size() * 95 / 100]));
  cv::Mat depth8;
  scan.depth.convertTo(depth8, CV_8U, 255.0 / scale_max);
  cv::Mat colours;
  cv::applyColorMap(255 - depth8, colours, cv::COLORMAP_JET);  // near red .. far blue
  // Sparse scans (a few points per hundred pixels) get dots; dense ones single pixels.
  const bool sparse = depths.size() < scan.depth.total() / 50;
  for (int v = 0; v < canvas.rows; ++v)
    for (int u = 0; u < canvas.cols; ++u) {
      if (scan.depth.at<float>(v, u) <= 0) continue;
      if (sparse)
        cv::circle(canvas, {u, v}, 1, colours.at<cv::Vec3b>(v, u), cv::FILLED);
      else
        canvas.at<cv::Vec3b>(v, u) = colours.at<cv::Vec3b>(v, u);
    }
  return canvas;
}

cv::Mat RenderCheckerboard(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                           const Isometry3& T_camera_lidar, int square_px) {
  cv::Mat canvas = ToBgr(image);
  const ProjectedScan scan = ProjectScan(cloud, camera, T_camera_lidar);
  // Densify the sparse LiDAR intensity image so that squares read as pictures, not dots.
  cv::Mat filled, mask = scan.depth > 0, grey;
  double max_intensity = 0;
  cv::minMaxLoc(scan.intensity, nullptr, &max_intensity);
  scan.intensity.convertTo(grey, CV_8U, max_intensity > 0 ? 255.0 / max_intensity : 1.0);
  cv::dilate(grey, filled, cv::Mat::ones(5, 5, CV_8U));
  cv::Mat lidar_bgr;
  cv::cvtColor(filled, lidar_bgr, cv::COLOR_GRAY2BGR);
  for (int v = 0; v < canvas.rows; ++v)
    for (int u = 0; u < canvas.cols; ++u)
      if (((u / square_px) + (v / square_px)) % 2 == 1) canvas.at<cv::Vec3b>(v, u) = lidar_bgr.at<cv::Vec3b>(v, u);
  return canvas;
}

double DepthEdgeToImageEdgeDistance(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                                    const Isometry3& T_camera_lidar) {
  const ProjectedScan scan = ProjectScan(cloud, camera, T_camera_lidar);
  cv::Mat grey, edges;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  cv::GaussianBlur(grey, grey, {5, 5}, 1.5);
  cv::Canny(grey, edges, 40, 120);
  cv::Mat not_edges = edges == 0, distance;
  cv::distanceTransform(not_edges, distance, cv::DIST_L2, 3);
  // A depth discontinuity: a point whose horizontal neighbour (within 3 px) is >= 30% nearer or farther.
  double sum = 0;
  int count = 0;
  for (int v = 0; v < scan.depth.rows; ++v) {
    const float* row = scan.depth.ptr<float>(v);
    int last_u = -1;
    for (int u = 0; u < scan.depth.cols; ++u) {
      if (row[u] <= 0) continue;
      if (last_u >= 0 && u - last_u <= 3) {
        const float a = row[last_u], b = row[u];
        if (std::max(a, b) > 1.3f * std::min(a, b)) {
          const int near_u = a < b ? last_u : u;  // the foreground side carries the object edge
          sum += distance.at<float>(v, near_u);
          ++count;
        }
      }
      last_u = u;
    }
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::infinity();
}

}  // namespace fusecal
