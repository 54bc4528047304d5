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

/// Gauss-Newton on the pose graph (paper IV-D): linearise every edge, assemble the normal
/// equations of the free nodes (all but node 0, which stays fixed as the reference), solve with
/// the LinearSolver, update T_k <- T_k exp(d_k). A free node without residuals keeps its pose.
template <PoseGraphEnergy EnergyT, LinearSolver Solver>
OptimizationReport optimizePoseGraph(const EnergyT& energy, const Solver& solver, const std::vector<const Keyframe*>& nodes,
                                     const std::vector<GraphEdge>& edges, const PinholeCameraf& grid_camera,
                                     std::vector<SE3d>& poses, const GaussNewtonSettings& settings = {}) {
  OptimizationReport report;
  const int free_nodes = int(nodes.size()) - 1;
  if (free_nodes <= 0) return report;
  const int n = 6 * free_nodes;
  Eigen::MatrixXd H(n, n);
  Eigen::VectorXd b(n), delta(n);
  std::vector<PairSystem> pairs(edges.size());
  for (int iteration = 0; iteration < settings.iterations; ++iteration) {
    H.setZero();
    b.setZero();
    double cost = 0.0;
    int residuals = 0;
    // Edges linearise independently (in parallel); the scatter below is serial and ordered, so the
    // result does not depend on the thread schedule.
    cv::parallel_for_(cv::Range(0, int(edges.size())), [&](const cv::Range& range) {
      for (int e = range.start; e < range.end; ++e) {
        const GraphEdge& edge = edges[std::size_t(e)];
        pairs[std::size_t(e)] = PairSystem();
        energy.linearise(
            PairInput{*nodes[edge.i], *nodes[edge.j], poses[edge.i], poses[edge.j], *edge.matches, grid_camera},
            pairs[std::size_t(e)]);
      }
    });
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
