#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

namespace bundletrack {

/// Exact nearest-neighbour queries on a fixed 3-D point set (ADD-S), by nanoflann's k-d tree
/// (libnanoflann-dev): leaves of up to 10 points, subtrees pruned by their distance to the query,
/// so queries far from the cloud (a wrong pose scored) stay cheap.
class KdTree3 {
 public:
  explicit KdTree3(std::vector<Eigen::Vector3f> points)
      : cloud_(std::make_unique<Cloud>(Cloud{std::move(points)})), index_(std::make_unique<Index>(3, *cloud_)) {}

  std::size_t size() const { return cloud_->points.size(); }

  /// Squared distance to the nearest point (infinity for an empty tree).
  float nearestSquaredDistance(const Eigen::Vector3f& q) const {
    if (cloud_->points.empty()) return std::numeric_limits<float>::infinity();
    std::uint32_t nearest = 0;
    float squared = 0.0f;
    nanoflann::KNNResultSet<float, std::uint32_t> result(1);
    result.init(&nearest, &squared);
    index_->findNeighbors(result, q.data(), nanoflann::SearchParams());
    return (cloud_->points[nearest] - q).squaredNorm();
  }

 private:
  /// The points as nanoflann's dataset adaptor sees them.
  struct Cloud {
    std::vector<Eigen::Vector3f> points;
    std::size_t kdtree_get_point_count() const { return points.size(); }
    float kdtree_get_pt(std::size_t i, std::size_t axis) const { return points[i][Eigen::Index(axis)]; }
    template <typename Box>
    bool kdtree_get_bbox(Box&) const {
      return false;  // nanoflann computes the bounding box
    }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, std::uint32_t>;

  std::unique_ptr<Cloud> cloud_;  // on the heap: the index refers to it, and the tree stays movable
  std::unique_ptr<Index> index_;
};

}  // namespace bundletrack
