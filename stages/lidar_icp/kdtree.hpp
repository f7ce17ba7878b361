// A 3-D k-d tree over a point vector (nanoflann, header-only). The tree keeps a pointer to the points:
// they must outlive it and must not change.
#pragma once

#include <nanoflann.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

namespace fusecal::lidar_icp {

class KdTree {
 public:
  explicit KdTree(const std::vector<Eigen::Vector3f>& points) : adaptor_(new Adaptor{&points}) {
    index_.reset(new Index(3, *adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(12)));
  }

  size_t size() const { return adaptor_->points->size(); }

  // Nearest point: false when the tree is empty.
  bool Nearest(const Eigen::Vector3f& q, uint32_t* index, float* sq_dist) const {
    if (size() == 0) return false;
    nanoflann::KNNResultSet<float, uint32_t> result(1);
    result.init(index, sq_dist);
    index_->findNeighbors(result, q.data(), SearchParams());
    return result.size() == 1;
  }

  // k nearest points, sorted by distance; returns how many were found (<= k).
  size_t Knn(const Eigen::Vector3f& q, size_t k, uint32_t* indices, float* sq_dists) const {
    if (size() == 0 || k == 0) return 0;
    nanoflann::KNNResultSet<float, uint32_t> result(k);
    result.init(indices, sq_dists);
    index_->findNeighbors(result, q.data(), SearchParams());
    return result.size();
  }

 private:
#if defined(NANOFLANN_VERSION) && NANOFLANN_VERSION >= 0x150
  using SearchParams = nanoflann::SearchParameters;
#else
  using SearchParams = nanoflann::SearchParams;
#endif
  struct Adaptor {
    const std::vector<Eigen::Vector3f>* points;
    size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][dim]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
      return false;
    }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Adaptor>, Adaptor, 3, uint32_t>;
  std::unique_ptr<Adaptor> adaptor_;
  std::unique_ptr<Index> index_;
};

}  // namespace fusecal::lidar_icp
