#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/energy.hpp"
#include "bundletrack/solvers/linear_solver.hpp"

namespace bundletrack {

struct GaussNewtonSettings {
  int iterations = 7;  ///< the original code's 7 outer iterations
  double min_update = 1e-7;  ///< stop when no pose moves more than this (max |d|, metres and radians)
};

/// An edge of the pose graph with its feature correspondences (first = node i, second = node j).
struct GraphEdge {
  int i = 0, j = 0;
  const std::vector<FeatureMatch>* matches = nullptr;
};

struct OptimizationReport {
  int iterations = 0;
  double initial_cost = 0.0;  ///< energy at the start
  double final_cost = 0.0;  ///< energy at the last linearisation (before its update)
  int residuals = 0;  ///< in the last linearisation
};

/// Assembles the normal equations of the free nodes (all but node 0) at the given poses: H (6k x
/// 6k, k = nodes - 1) and b = J^T W r. Edges linearise independently (in parallel, or all in one
/// call for an energy with lineariseAll); the scatter is serial and ordered, so the result does
/// not depend on the thread schedule. Returns the cost and writes the number of residuals.
template <PoseGraphEnergy EnergyT>
double assembleNormalEquations(const EnergyT& energy, const std::vector<const Keyframe*>& nodes,
                               const std::vector<GraphEdge>& edges, const PinholeCameraf& grid_camera,
                               const std::vector<SE3d>& poses, Eigen::MatrixXd& H, Eigen::VectorXd& b,
                               int& residuals) {
  const int n = 6 * (int(nodes.size()) - 1);
  H.setZero(n, n);
  b.setZero(n);
  std::vector<PairSystem> pairs(edges.size());
  std::vector<PairInput> inputs;
  inputs.reserve(edges.size());
  for (const GraphEdge& edge : edges)
    inputs.push_back({*nodes[edge.i], *nodes[edge.j], poses[edge.i], poses[edge.j], *edge.matches, grid_camera});
  if constexpr (requires { energy.lineariseAll(std::span<const PairInput>(inputs), std::span<PairSystem>(pairs)); }) {
    energy.lineariseAll(inputs, pairs);
  } else {
    cv::parallel_for_(cv::Range(0, int(edges.size())), [&](const cv::Range& range) {
      for (int e = range.start; e < range.end; ++e) energy.linearise(inputs[std::size_t(e)], pairs[std::size_t(e)]);
    });
  }
  double cost = 0.0;
  residuals = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const GraphEdge& edge = edges[e];
    const PairSystem& pair = pairs[e];
    cost += pair.cost;
    residuals += pair.residuals;
    const int index[2] = {edge.i - 1, edge.j - 1};  // node 0 is fixed: it has no unknowns
    for (int a = 0; a < 2; ++a) {
      if (index[a] < 0) continue;
      b.segment<6>(6 * index[a]) += pair.b.segment<6>(6 * a);
      for (int c = 0; c < 2; ++c)
        if (index[c] >= 0) H.block<6, 6>(6 * index[a], 6 * index[c]) += pair.H.block<6, 6>(6 * a, 6 * c);
    }
  }
  return cost;
}

/// Gauss-Newton on the pose graph (paper IV-D): assemble the normal equations of the free nodes
/// (node 0 stays fixed as the reference), solve with the LinearSolver, update T_k <- T_k exp(d_k).
/// A free node without residuals keeps its pose.
template <PoseGraphEnergy EnergyT, LinearSolver Solver>
OptimizationReport optimizePoseGraph(const EnergyT& energy, const Solver& solver, const std::vector<const Keyframe*>& nodes,
                                     const std::vector<GraphEdge>& edges, const PinholeCameraf& grid_camera,
                                     std::vector<SE3d>& poses, const GaussNewtonSettings& settings = {}) {
  OptimizationReport report;
  const int free_nodes = int(nodes.size()) - 1;
  if (free_nodes <= 0) return report;
  Eigen::MatrixXd H;
  Eigen::VectorXd b, delta;
  for (int iteration = 0; iteration < settings.iterations; ++iteration) {
    int residuals = 0;
    const double cost = assembleNormalEquations(energy, nodes, edges, grid_camera, poses, H, b, residuals);
    if (iteration == 0) report.initial_cost = cost;
    report.final_cost = cost;
    report.residuals = residuals;
    if (residuals == 0) break;
    for (int k = 0; k < free_nodes; ++k)
      if (H.block<6, 6>(6 * k, 6 * k).isZero()) H.block<6, 6>(6 * k, 6 * k).setIdentity();
    solver.solve(H, -b, delta);
    for (int k = 0; k < free_nodes; ++k) poses[k + 1] = poses[k + 1] * SE3d::exp(delta.segment<6>(6 * k));
    report.iterations = iteration + 1;
    if (delta.cwiseAbs().maxCoeff() < settings.min_update) break;
  }
  return report;
}

}  // namespace bundletrack
