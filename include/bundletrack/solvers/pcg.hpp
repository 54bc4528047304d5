#pragma once

#include <cmath>
#include <vector>

#include "bundletrack/solvers/block_jacobi.hpp"
#include "bundletrack/solvers/linear_solver.hpp"

namespace bundletrack {

/// Preconditioned conjugate gradients (paper IV-D) with the block-Jacobi preconditioner of
/// blockJacobiInverse. Stops after max_iterations or when |H x - rhs| <= tolerance |rhs|.
struct PCG {
  int max_iterations = 5;  ///< the original code's 5 inner iterations per Gauss-Newton step
  double tolerance = 1e-10;
  double damping = 1e-9;

  SolveReport solve(const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const {
    const Eigen::Index n = H.rows(), blocks = n / 6;
    std::vector<Eigen::Matrix<double, 6, 6>> inverse(static_cast<std::size_t>(blocks));
    blockJacobiInverse(H, damping, [&](Eigen::Index k, const Eigen::Matrix<double, 6, 6>& block_inverse) {
      inverse[std::size_t(k)] = block_inverse;
    });
    const auto precondition = [&](const Eigen::VectorXd& r) {
      Eigen::VectorXd z(n);
      for (Eigen::Index k = 0; k < blocks; ++k) z.segment<6>(6 * k) = inverse[std::size_t(k)] * r.segment<6>(6 * k);
      return z;
    };
    x = Eigen::VectorXd::Zero(n);
    const double rhs_norm = rhs.norm();
    if (rhs_norm == 0.0) return {0, 0.0};
    Eigen::VectorXd r = rhs, z = precondition(r), p = z;
    double rz = r.dot(z);
    int iteration = 0;
    while (iteration < max_iterations && r.norm() > tolerance * rhs_norm) {
      const Eigen::VectorXd Hp = H * p;
      const double pHp = p.dot(Hp);
      if (!(pHp > 0.0)) break;  // no positive curvature left along p
      const double alpha = rz / pHp;
      x += alpha * p;
      r -= alpha * Hp;
      z = precondition(r);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
      ++iteration;
    }
    return {iteration, r.norm() / rhs_norm};
  }
};

}  // namespace bundletrack
