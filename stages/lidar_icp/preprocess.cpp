#include "stages/lidar_icp/preprocess.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace fusecal::lidar_icp {

std::vector<Eigen::Vector3f> ValidPoints(const PointCloud& scan, double min_range_m, double max_range_m) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(scan.points.size());
  const float min_sq = static_cast<float>(min_range_m * min_range_m);
  const float max_sq = static_cast<float>(max_range_m * max_range_m);
  for (const Eigen::Vector3f& p : scan.points) {
    if (!p.allFinite()) continue;
    const float r2 = p.squaredNorm();
    if (r2 < min_sq || r2 > max_sq) continue;
    out.push_back(p);
  }
  return out;
}

double MedianRange(const std::vector<Eigen::Vector3f>& points) {
  if (points.empty()) return 0.0;
  const size_t stride = std::max<size_t>(1, points.size() / 4000);
  std::vector<float> ranges;
  ranges.reserve(points.size() / stride + 1);
  for (size_t i = 0; i < points.size(); i += stride) ranges.push_back(points[i].norm());
  auto mid = ranges.begin() + ranges.size() / 2;
  std::nth_element(ranges.begin(), mid, ranges.end());
  return *mid;
}

namespace {

// A voxel: its key (21 bits per axis around the origin: +-1e6 voxels, far beyond any range crop), and the
// sum and count of its points.
struct Voxel {
  uint64_t key;
  Eigen::Vector3d sum;
  uint32_t count;
};
constexpr int64_t kHalf = int64_t(1) << 20;
// NeighbourhoodVoxelCentroids: a voxel with fewer points than 1 / kTailRatio of its densest neighbour's
// holds the tail of the noise off a surface that runs through that neighbour.
constexpr uint32_t kTailRatio = 3;

// The occupied voxels, sorted by key. Points in the outermost voxel layer of the key space are dropped, so
// that every voxel has 26 neighbours with valid keys.
std::vector<Voxel> Voxelize(const std::vector<Eigen::Vector3f>& points, double voxel_m) {
  const double inv = 1.0 / voxel_m;
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  keyed.reserve(points.size());
  for (uint32_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const int64_t x = static_cast<int64_t>(std::floor(p.x() * inv)) + kHalf;
    const int64_t y = static_cast<int64_t>(std::floor(p.y() * inv)) + kHalf;
    const int64_t z = static_cast<int64_t>(std::floor(p.z() * inv)) + kHalf;
    if (std::min({x, y, z}) < 1 || std::max({x, y, z}) >= 2 * kHalf - 1) continue;
    keyed.emplace_back((uint64_t(x) << 42) | (uint64_t(y) << 21) | uint64_t(z), i);
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<Voxel> voxels;
  for (size_t begin = 0; begin < keyed.size();) {
    Voxel v{keyed[begin].first, Eigen::Vector3d::Zero(), 0};
    for (; begin + v.count < keyed.size() && keyed[begin + v.count].first == v.key; ++v.count)
      v.sum += points[keyed[begin + v.count].second].cast<double>();
    voxels.push_back(v);
    begin += v.count;
  }
  return voxels;
}

}  // namespace

std::vector<Eigen::Vector3f> VoxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel_m) {
  std::vector<Eigen::Vector3f> out;
  for (const Voxel& v : Voxelize(points, voxel_m)) out.push_back((v.sum / double(v.count)).cast<float>());
  return out;
}

std::vector<Eigen::Vector3f> NeighbourhoodVoxelCentroids(const std::vector<Eigen::Vector3f>& points, double voxel_m) {
  const std::vector<Voxel> voxels = Voxelize(points, voxel_m);
  const auto before = [](const Voxel& v, uint64_t key) { return v.key < key; };
  std::vector<Eigen::Vector3f> out;
  out.reserve(voxels.size());
  for (const Voxel& v : voxels) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double count = 0;
    uint32_t densest = 0;
    for (int64_t dx = -1; dx <= 1; ++dx) {
      for (int64_t dy = -1; dy <= 1; ++dy) {
        // The three voxels along z are neighbours in key order: one search per (dx, dy).
        const uint64_t first = v.key + (uint64_t(dx) << 42) + (uint64_t(dy) << 21) - 1;
        for (auto it = std::lower_bound(voxels.begin(), voxels.end(), first, before);
             it != voxels.end() && it->key <= first + 2; ++it) {
          sum += it->sum;
          count += it->count;
          densest = std::max(densest, it->count);
        }
      }
    }
    if (v.count * kTailRatio < densest) continue;
    out.push_back((sum / count).cast<float>());
  }
  return out;
}

std::vector<Eigen::Vector3f> Subsample(const std::vector<Eigen::Vector3f>& points, size_t max_count) {
  if (points.size() <= max_count) return points;
  std::vector<uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  std::mt19937 rng(42);
  // Partial Fisher-Yates with our own index draw, so the subset does not depend on the library.
  for (size_t i = 0; i < max_count; ++i) {
    const size_t j = i + rng() % (order.size() - i);
    std::swap(order[i], order[j]);
  }
  order.resize(max_count);
  std::sort(order.begin(), order.end());
  std::vector<Eigen::Vector3f> out;
  out.reserve(max_count);
  for (uint32_t i : order) out.push_back(points[i]);
  return out;
}

void EstimateNormals(const std::vector<Eigen::Vector3f>& points, const KdTree& tree, int k, int threads,
                     std::vector<Eigen::Vector3f>* normals, std::vector<uint8_t>* planar) {
  const int n = static_cast<int>(points.size());
  normals->assign(points.size(), Eigen::Vector3f::Zero());
  planar->assign(points.size(), 0);
#pragma omp parallel num_threads(threads)
  {
    std::vector<uint32_t> idx(k);
    std::vector<float> d2(k);
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      const size_t found = tree.Knn(points[i], k, idx.data(), d2.data());
      if (found < 5) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t j = 0; j < found; ++j) mean += points[idx[j]].cast<double>();
      mean /= double(found);
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (size_t j = 0; j < found; ++j) {
        const Eigen::Vector3d d = points[idx[j]].cast<double>() - mean;
        cov += d * d.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
      eig.computeDirect(cov);
      const Eigen::Vector3d ev = eig.eigenvalues();  // ascending
      // A plane: smallest eigenvalue well below the middle one; not a line: middle not tiny vs largest.
      if (!(ev(1) > 1e-10) || ev(0) > 0.25 * ev(1) || ev(1) < 0.01 * ev(2)) continue;
      (*normals)[i] = eig.eigenvectors().col(0).normalized().cast<float>();
      (*planar)[i] = 1;
    }
  }
}

void PreparedCloud::BuildTarget(int normal_neighbors, int threads) {
  tree = std::make_unique<KdTree>(points);
  EstimateNormals(points, *tree, normal_neighbors, threads, &normals, &planar);
}

}  // namespace fusecal::lidar_icp
