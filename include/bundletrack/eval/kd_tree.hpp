#pragma once

#include <algorithm>
#include <limits>
#include <numeric>
#include <vector>

#include <Eigen/Core>

namespace bundletrack {

/// Exact nearest-neighbour queries on a fixed 3-D point set: a k-d tree over an index array,
/// median split on the widest axis, leaves of up to 8 points.
class KdTree3 {
 public:
  explicit KdTree3(std::vector<Eigen::Vector3f> points) : points_(std::move(points)), order_(points_.size()) {
    std::iota(order_.begin(), order_.end(), 0);
    if (!points_.empty()) build(0, int(order_.size()));
  }

  std::size_t size() const { return points_.size(); }

  /// Squared distance to the nearest point (infinity for an empty tree).
  float nearestSquaredDistance(const Eigen::Vector3f& q) const {
    float best = std::numeric_limits<float>::infinity();
    if (!points_.empty()) search(0, q, best);
    return best;
  }

 private:
  struct Node {
    int begin, end;  // range of order_
    int axis = -1;  // -1: leaf
    float split = 0.0f;
    int left = -1, right = -1;
  };

  int build(int begin, int end) {
    const int id = int(nodes_.size());
    nodes_.push_back({begin, end});
    if (end - begin <= 8) return id;
    Eigen::Vector3f lo = points_[order_[begin]], hi = lo;
    for (int i = begin; i < end; ++i) lo = lo.cwiseMin(points_[order_[i]]), hi = hi.cwiseMax(points_[order_[i]]);
    int axis;
    (hi - lo).maxCoeff(&axis);
    const int mid = (begin + end) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](int a, int b) { return points_[a][axis] < points_[b][axis]; });
    const float split = points_[order_[mid]][axis];
    const int left = build(begin, mid);
    const int right = build(mid, end);
    nodes_[id].axis = axis;
    nodes_[id].split = split;
    nodes_[id].left = left;
    nodes_[id].right = right;
    return id;
  }

  void search(int id, const Eigen::Vector3f& q, float& best) const {
    const Node& node = nodes_[id];
    if (node.axis < 0) {
      for (int i = node.begin; i < node.end; ++i) best = std::min(best, (points_[order_[i]] - q).squaredNorm());
      return;
    }
    const float diff = q[node.axis] - node.split;
    search(diff < 0.0f ? node.left : node.right, q, best);
    if (diff * diff < best) search(diff < 0.0f ? node.right : node.left, q, best);
  }

  std::vector<Eigen::Vector3f> points_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace bundletrack
