#pragma once

#include <concepts>
#include <span>

#include "bundletrack/graph/pose_graph.hpp"
#include "bundletrack/robust/losses.hpp"
#include "bundletrack/solvers/pair_system.hpp"

namespace bundletrack {

/// An energy term of the pose graph (paper eq. 2, 3). `T::input(edge)` takes from an edge of the
/// tracker's graph what the term reads (its `Input`: features, surfaces, ...), and
/// `linearise(input, T_i, T_j, loss, weight, system)` adds the term's robustly weighted residuals
/// of that edge at poses T_i, T_j to the edge's normal equations, for any RobustLoss.
template <typename T>
concept Residual = requires(const T& residual, const EdgeView& edge, const typename T::Input& input, const SE3d& pose,
                            const RobustLossArchetype& loss, PairSystem& system) {
  { T::input(edge) } -> std::same_as<typename T::Input>;
  { residual.linearise(input, pose, pose, loss, 1.0, system) } -> std::same_as<void>;
};

/// A residual that also linearises every edge of a graph in one call: systems[e] receives what
/// linearise(inputs[e], poses[edges[e].i], poses[edges[e].j], ...) would add (a GPU backend: one
/// launch for the whole graph).
template <typename T>
concept BatchResidual =
    Residual<T> && requires(const T& residual, std::span<const typename T::Input> inputs, std::span<const GraphEdge> edges,
                            std::span<const SE3d> poses, const RobustLossArchetype& loss, std::span<PairSystem> systems) {
      { residual.lineariseAll(inputs, edges, poses, loss, 1.0, systems) } -> std::same_as<void>;
    };

}  // namespace bundletrack
