#pragma once

#include <concepts>
#include <span>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/solvers/pair_system.hpp"

namespace bundletrack {

/// An edge of a pose graph between nodes i and j (indices into the poses).
struct GraphEdge {
  int i = 0, j = 0;
};

/// What Gauss-Newton needs of a pose graph: its edges, and each edge's normal equations at given
/// poses (systems[e] for edges()[e], over [d_i; d_j]). Whatever the residuals read (features,
/// surfaces, cameras) stays inside the problem.
template <typename T>
concept PoseGraphProblem = requires(const T& problem, std::span<const SE3d> poses, std::span<PairSystem> systems) {
  { problem.edges() } -> std::convertible_to<std::span<const GraphEdge>>;
  { problem.linearise(poses, systems) } -> std::same_as<void>;
};

}  // namespace bundletrack
