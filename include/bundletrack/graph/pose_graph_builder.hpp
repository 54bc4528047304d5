#pragma once

#include <algorithm>
#include <vector>

#include "bundletrack/core/execution.hpp"
#include "bundletrack/graph/correspondence_cache.hpp"
#include "bundletrack/graph/keyframe_pool.hpp"
#include "bundletrack/graph/pose_graph.hpp"

namespace bundletrack {

/// The current frame's link to the last good frame: that frame's id and, when the coarse pose came
/// from it, RANSAC's inliers (paper IV-B), which become their edge's correspondences.
struct LastFrameLink {
  int id = -1;
  std::vector<FeatureMatch>* inliers = nullptr;  ///< moved from; null: the edge is matched anew
};

/// Paper IV-C, IV-D: the pose graph of `current` at `T_current` over the keyframes the pool selects
/// for that rotation (at most max_keyframes), every pair an edge. match_edge(a, b, T_a, T_b) gives
/// the feature correspondences of a pair under the poses; keyframe pairs are matched once, at their
/// stored poses, and come from `cache` after that. The current frame's edges are matched first, on
/// OpenCV's threads where `execution` is Parallel (match_edge must then allow concurrent calls);
/// the graph does not depend on it.
template <typename MatchEdge>
PoseGraph buildPoseGraph(const KeyframePool& pool, std::size_t max_keyframes, const Keyframe& current,
                         const SE3d& T_current, LastFrameLink last, CorrespondenceCache& cache, MatchEdge&& match_edge,
                         Execution execution = Execution::Serial) {
  PoseGraph graph;
  graph.pool_indices = pool.select(T_current.rotation(), max_keyframes);
  // Ascending ids put frame 0 first (the fixed node) and give every keyframe pair one orientation.
  std::sort(graph.pool_indices.begin(), graph.pool_indices.end());
  for (const std::size_t k : graph.pool_indices) graph.nodes.push_back(&pool[k]), graph.poses.push_back(pool[k].T_cam_obj);
  graph.nodes.push_back(&current);
  graph.poses.push_back(T_current);
  const int current_node = int(graph.nodes.size()) - 1;
  const auto linked_to_last = [&](const Keyframe& node) { return node.id == last.id && last.inliers != nullptr; };
  std::vector<std::vector<FeatureMatch>> to_current(static_cast<std::size_t>(current_node));
  forEachIndex(execution, current_node, [&](int a) {
    const Keyframe& first = *graph.nodes[std::size_t(a)];
    if (!linked_to_last(first)) to_current[std::size_t(a)] = match_edge(first, current, graph.poses[std::size_t(a)], T_current);
  });
  for (int a = 0; a < current_node; ++a) {
    for (int b = a + 1; b <= current_node; ++b) {
      const Keyframe& first = *graph.nodes[std::size_t(a)];
      if (b == current_node) {
        graph.matches.push_back(
            &graph.owned_matches.emplace_back(linked_to_last(first) ? std::move(*last.inliers) : std::move(to_current[std::size_t(a)])));
      } else {
        graph.matches.push_back(&cache.get(first, *graph.nodes[std::size_t(b)], [&](const Keyframe& i, const Keyframe& j) {
          return match_edge(i, j, i.T_cam_obj, j.T_cam_obj);
        }));
      }
      graph.edges.push_back({a, b});
    }
  }
  return graph;
}

}  // namespace bundletrack
