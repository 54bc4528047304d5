#pragma once

#include <deque>
#include <vector>

#include "bundletrack/graph/keyframe.hpp"
#include "bundletrack/solvers/pose_graph_problem.hpp"

namespace bundletrack {

/// One edge of the tracker's pose graph as a residual sees it: both keyframes and the edge's
/// feature correspondences (first = i, second = j). A residual takes from it what it needs.
struct EdgeView {
  const Keyframe& i;
  const Keyframe& j;
  const std::vector<FeatureMatch>& matches;
};

/// The pose graph of one frame (paper IV-C, IV-D): the selected keyframes in ascending id (frame 0
/// first: the fixed node), then the current frame; their poses; every pair as an edge with its
/// feature correspondences.
struct PoseGraph {
  PoseGraph() = default;
  PoseGraph(PoseGraph&&) = default;
  PoseGraph& operator=(PoseGraph&&) = default;
  PoseGraph(const PoseGraph&) = delete;  // matches point into owned_matches

  std::vector<const Keyframe*> nodes;
  std::vector<std::size_t> pool_indices;  ///< where the keyframe nodes (all but the last) sit in the pool
  std::vector<SE3d> poses;
  std::vector<GraphEdge> edges;
  std::vector<const std::vector<FeatureMatch>*> matches;  ///< per edge
  std::deque<std::vector<FeatureMatch>> owned_matches;  ///< correspondences the graph owns (the tracker: the current frame's edges); stable addresses

  EdgeView edge(std::size_t e) const { return {*nodes[std::size_t(edges[e].i)], *nodes[std::size_t(edges[e].j)], *matches[e]}; }
};

}  // namespace bundletrack
