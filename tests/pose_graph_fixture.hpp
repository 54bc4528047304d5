#pragma once

#include <vector>

#include "bundletrack/graph/pose_graph.hpp"

/// A pose graph over `keyframes` at `poses`, every pair a < b an edge with the same `matches`.
inline bundletrack::PoseGraph allPairsGraph(const std::vector<bundletrack::Keyframe>& keyframes,
                                            std::vector<bundletrack::SE3d> poses,
                                            const std::vector<bundletrack::FeatureMatch>& matches) {
  bundletrack::PoseGraph graph;
  for (const auto& k : keyframes) graph.nodes.push_back(&k);
  graph.poses = std::move(poses);
  for (int a = 0; a < int(keyframes.size()); ++a)
    for (int b = a + 1; b < int(keyframes.size()); ++b) graph.edges.push_back({a, b}), graph.matches.push_back(&matches);
  return graph;
}
