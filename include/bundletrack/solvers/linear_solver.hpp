#pragma once

#include <concepts>

#include <Eigen/Core>

namespace bundletrack {

struct SolveReport {
  int iterations = 0;
  double relative_residual = 0.0;  ///< |H x - rhs| / |rhs|
};

/// Solves the (symmetric positive semi-definite) normal equations H x = rhs of the free nodes,
/// 6 unknowns per node in node order.
template <typename T>
concept LinearSolver = requires(const T& solver, const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs,
                                Eigen::VectorXd& x) {
  { solver.solve(H, rhs, x) } -> std::same_as<SolveReport>;
};

}  // namespace bundletrack
