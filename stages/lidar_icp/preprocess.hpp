// Scan preprocessing for registration: validity and range crop, voxel downsampling, even subsampling,
// target normals by a k-NN plane fit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "stages/foundation/point_cloud.hpp"
#include "stages/lidar_icp/kdtree.hpp"

namespace fusecal::lidar_icp {

// Finite points with range in [min_range_m, max_range_m] from the sensor origin.
std::vector<Eigen::Vector3f> ValidPoints(const PointCloud& scan, double min_range_m, double max_range_m);

// Median distance from the origin (of at most ~4000 evenly spread points); 0 when empty.
double MedianRange(const std::vector<Eigen::Vector3f>& points);

// One point per occupied voxel: the centroid of its points (which keeps planar surfaces unbiased and
// averages range noise). Output order is deterministic (sorted by voxel key).
std::vector<Eigen::Vector3f> VoxelDownsample(const std::vector<Eigen::Vector3f>& points, double voxel_m);

// One point per occupied voxel: the centroid of the points in the 3 x 3 x 3 voxels around it. With range
// noise not far below the voxel size, a voxel's own centroid is pulled toward the voxel's centre (the
// voxel cuts the noise's spread across a surface), by an amount that follows the grid, and two scans lie
// differently in it: ICP slides by the difference (2 cm of range noise, 5 cm voxels, Livox Avia-like
// accumulated clouds: 0.068 deg / 5.3 mm rms per registration from voxel centroids, 0.009 deg / 0.6 mm
// from these). The neighbourhood reaches the whole spread of the noise, so its centroid lies on the
// surface, except for a voxel that holds only the noise's tail beyond the surface (fewer than a third of
// the points of its densest neighbour): such a voxel is left out.
std::vector<Eigen::Vector3f> NeighbourhoodVoxelCentroids(const std::vector<Eigen::Vector3f>& points, double voxel_m);

// At most max_count points, a fixed-seed random subset (deterministic).
std::vector<Eigen::Vector3f> Subsample(const std::vector<Eigen::Vector3f>& points, size_t max_count);

// Unit normals from the k nearest neighbours; planar[i] = 0 where the neighbourhood is not a plane
// (corner, edge, a single scan line, too few neighbours) and the normal must not be used.
void EstimateNormals(const std::vector<Eigen::Vector3f>& points, const KdTree& tree, int k, int threads,
                     std::vector<Eigen::Vector3f>* normals, std::vector<uint8_t>* planar);

// A scan ready to be registered as target (normals, tree) or source.
// Not copyable or movable: the tree points into `points`.
struct PreparedCloud {
  PreparedCloud() = default;
  PreparedCloud(const PreparedCloud&) = delete;
  PreparedCloud& operator=(const PreparedCloud&) = delete;

  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;  // target only
  std::vector<uint8_t> planar;           // target only
  std::unique_ptr<KdTree> tree;          // target only

  void BuildTarget(int normal_neighbors, int threads);
};

}  // namespace fusecal::lidar_icp
