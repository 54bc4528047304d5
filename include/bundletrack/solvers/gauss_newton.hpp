#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>

#include "bundletrack/solvers/linear_solver.hpp"
#include "bundletrack/solvers/pose_graph_problem.hpp"

namespace bundletrack {

/// How a Gauss-Newton step is taken.
enum class StepControl {
  None,  ///< the plain Gauss-Newton step, always taken (the paper and the original code)
  /// Levenberg-Marquardt: H + lambda diag(H); a step that raises the cost is rejected and retried
  /// with 10x lambda, an accepted one divides lambda by 10.
  LevenbergMarquardt,
};

struct GaussNewtonSettings {
  int iterations = 7;  ///< linearisations per optimisation: the original code's 7 outer iterations
  double min_translation_step = 1e-7;  ///< metres; stop when no node moves more, and ...
  double min_rotation_step = 1e-7;  ///< ... radians: no node turns more
  StepControl step_control = StepControl::None;
  double initial_damping = 1e-4;  ///< lambda of the first Levenberg-Marquardt step
};

struct OptimizationReport {
  int iterations = 0;  ///< steps taken
  int rejected_steps = 0;  ///< Levenberg-Marquardt steps that raised the cost
  double initial_cost = 0.0;  ///< energy at the start
  double final_cost = 0.0;  ///< energy at the last linearisation
  int residuals = 0;  ///< in the last linearisation
  std::vector<SolveReport> solves;  ///< the linear solver's report of every step, taken or not
  Eigen::MatrixXd information;  ///< H of the last linearisation, over the free nodes (empty when none)
};

/// The energy and its normal equations at given poses.
struct Linearisation {
  Eigen::MatrixXd H;  ///< 6k x 6k over the free nodes (all but node 0)
  Eigen::VectorXd b;  ///< J^T W r
  double cost = 0.0;
  int residuals = 0;
};

/// Assembles the normal equations of the free nodes (node 0 is fixed). Edges linearise
/// independently (the problem may do so in parallel); the scatter is serial and in edge order,
/// so the result does not depend on the thread schedule.
template <PoseGraphProblem Problem>
void assembleNormalEquations(const Problem& problem, std::span<const SE3d> poses, Linearisation& out) {
  const std::span<const GraphEdge> edges = problem.edges();
  const int n = 6 * (int(poses.size()) - 1);
  out.H.setZero(n, n);
  out.b.setZero(n);
  std::vector<PairSystem> pairs(edges.size());
  problem.linearise(poses, pairs);
  out.cost = 0.0;
  out.residuals = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const PairSystem& pair = pairs[e];
    out.cost += pair.cost;
    out.residuals += pair.residuals;
    const int index[2] = {edges[e].i - 1, edges[e].j - 1};
    for (int a = 0; a < 2; ++a) {
      if (index[a] < 0) continue;
      out.b.segment<6>(6 * index[a]) += pair.b.segment<6>(6 * a);
      for (int c = 0; c < 2; ++c)
        if (index[c] >= 0) out.H.block<6, 6>(6 * index[a], 6 * index[c]) += pair.H.block<6, 6>(6 * a, 6 * c);
    }
  }
}

namespace detail {

/// Solves for the step of the free nodes: (H + lambda diag(H)) d = -b, a node without residuals
/// (zero block) kept in place by an identity block.
template <LinearSolver Solver>
SolveReport solveStep(const Solver& solver, Eigen::MatrixXd H, const Eigen::VectorXd& b, double lambda,
                      Eigen::VectorXd& step) {
  for (Eigen::Index k = 0; k < H.rows() / 6; ++k)
    if (H.block<6, 6>(6 * k, 6 * k).isZero()) H.block<6, 6>(6 * k, 6 * k).setIdentity();
  if (lambda > 0.0) H.diagonal() *= 1.0 + lambda;
  return solver.solve(H, -b, step);
}

/// T_k <- T_k exp(d_k) for the free nodes (right perturbations, docs/DESIGN.md section 2).
inline std::vector<SE3d> moved(std::vector<SE3d> poses, const Eigen::VectorXd& step) {
  for (std::size_t k = 1; k < poses.size(); ++k)
    poses[k] = poses[k] * SE3d::exp(step.segment<6>(6 * Eigen::Index(k - 1)));
  return poses;
}

/// Whether no node moves by min_translation_step or turns by min_rotation_step.
inline bool negligible(const Eigen::VectorXd& step, const GaussNewtonSettings& settings) {
  double translation = 0.0, rotation = 0.0;
  for (Eigen::Index k = 0; k < step.size() / 6; ++k) {
    translation = std::max(translation, step.segment<3>(6 * k).cwiseAbs().maxCoeff());
    rotation = std::max(rotation, step.segment<3>(6 * k + 3).cwiseAbs().maxCoeff());
  }
  return translation < settings.min_translation_step && rotation < settings.min_rotation_step;
}

}  // namespace detail

/// Gauss-Newton on the pose graph (paper IV-D): node 0 stays fixed as the reference, the others
/// move by T_k <- T_k exp(d_k) with d from the LinearSolver. `poses` holds every node's pose in
/// problem order and receives the result. With StepControl::None every step is taken; with
/// LevenbergMarquardt a step is kept only when it lowers the energy (each try costs one
/// linearisation, which an accepted step reuses as the next one's).
template <PoseGraphProblem Problem, LinearSolver Solver>
OptimizationReport optimizePoseGraph(const Problem& problem, const Solver& solver, std::vector<SE3d>& poses,
                                     const GaussNewtonSettings& settings = {}) {
  OptimizationReport report;
  if (poses.size() < 2) return report;
  Linearisation at;
  Eigen::VectorXd step;
  const bool damped = settings.step_control == StepControl::LevenbergMarquardt;
  double lambda = damped ? settings.initial_damping : 0.0;
  for (int iteration = 0; iteration < settings.iterations; ++iteration) {
    if (iteration == 0 || !damped) {
      assembleNormalEquations(problem, std::span<const SE3d>(poses), at);
      if (iteration == 0) report.initial_cost = at.cost;
      report.final_cost = at.cost;
      report.residuals = at.residuals;
    }
    if (at.residuals == 0) break;
    report.solves.push_back(detail::solveStep(solver, at.H, at.b, lambda, step));
    std::vector<SE3d> candidate = detail::moved(poses, step);
    if (damped) {
      Linearisation next;
      assembleNormalEquations(problem, std::span<const SE3d>(candidate), next);
      if (!(next.cost < at.cost)) {
        ++report.rejected_steps;
        lambda *= 10.0;
        continue;
      }
      lambda /= 10.0;
      at = std::move(next);
      report.final_cost = at.cost;
      report.residuals = at.residuals;
    }
    poses = std::move(candidate);
    report.iterations = iteration + 1;
    if (detail::negligible(step, settings)) break;
  }
  report.information = std::move(at.H);
  return report;
}

}  // namespace bundletrack
