#pragma once

#include <algorithm>
#include <limits>
#include <numeric>
#include <vector>

#include <Eigen/Core>

namespace bundletrack {

/// Exact nearest-neighbour queries on a fixed 3-D point set: a k-d tree over an index array,
/// median split on the widest axis, leaves of up to 8 points. A subtree is searched only when its
/// points' bounding box is nearer than the best point found so far; pruning by the distance to
/// the splitting plane alone visited nearly every node for queries far from the cloud (a wrong
/// pose when scoring ADD-S).
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
    Eigen::Vector3f lo, hi;  // bounding box of the node's points
    int axis = -1;  // -1: leaf
    float split = 0.0f;
    int left = -1, right = -1;
  };

  int build(int begin, int end) {
    const int id = int(nodes_.size());
    Eigen::Vector3f lo = points_[order_[begin]], hi = lo;
    for (int i = begin; i < end; ++i) lo = lo.cwiseMin(points_[order_[i]]), hi = hi.cwiseMax(points_[order_[i]]);
    nodes_.push_back({begin, end, lo, hi});
    if (end - begin <= 8) return id;
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
    const bool left_first = q[node.axis] < node.split;
    for (const int child : {left_first ? node.left : node.right, left_first ? node.right : node.left})
      if (boxSquaredDistance(nodes_[child], q) < best) search(child, q, best);
  }

  static float boxSquaredDistance(const Node& node, const Eigen::Vector3f& q) {
    return (q - q.cwiseMax(node.lo).cwiseMin(node.hi)).squaredNorm();
  }

  std::vector<Eigen::Vector3f> points_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace bundletrack
