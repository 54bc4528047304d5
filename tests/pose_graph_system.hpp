#pragma once

#include <random>
#include <utility>

#include <Eigen/Core>

#include "bundletrack/solvers/dense_ldlt.hpp"

// Normal equations shaped like a pose graph's: `nodes` free nodes, each residual coupling two of
// them, translation columns at scale 1 and rotation columns at 0.05 (a few-cm object), plus a
// small ridge. Symmetric positive definite, with the conditioning that makes preconditioning matter.
inline void poseGraphSystem(int nodes, unsigned seed, double ridge, Eigen::MatrixXd& H, Eigen::VectorXd& rhs) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const int n = 6 * nodes;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 * n, n);
  for (int r = 0; r < J.rows(); ++r) {
    const int a = (r / 6) % nodes, b = (a + 1 + r % 5) % nodes;
    for (int c = 0; c < 6; ++c) {
      J(r, 6 * a + c) += normal(rng) * (c < 3 ? 1.0 : 0.05);
      J(r, 6 * b + c) -= normal(rng) * (c < 3 ? 1.0 : 0.05);
    }
  }
  H = J.transpose() * J + ridge * Eigen::MatrixXd::Identity(n, n);
  rhs.resize(n);
  for (int k = 0; k < n; ++k) rhs[k] = normal(rng);
}

/// A PCG policy run on H x = rhs with the given iteration cap and tolerance, and how far its
/// solution lies from the dense LDLT solve (|x - x_dense| / |x_dense|).
template <typename Pcg>
std::pair<bundletrack::SolveReport, double> solveAgainstDense(Pcg pcg, int max_iterations, double tolerance,
                                                             const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs) {
  pcg.max_iterations = max_iterations;
  pcg.tolerance = tolerance;
  Eigen::VectorXd x, x_dense;
  const bundletrack::SolveReport report = pcg.solve(H, rhs, x);
  bundletrack::DenseLDLT().solve(H, rhs, x_dense);
  return {report, (x - x_dense).norm() / x_dense.norm()};
}
