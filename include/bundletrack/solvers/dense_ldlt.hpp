#pragma once

#include <Eigen/Cholesky>

#include "bundletrack/solvers/linear_solver.hpp"

namespace bundletrack {

/// Direct solve by a robust Cholesky (LDL^T with pivoting) of the assembled normal matrix.
struct DenseLDLT {
  SolveReport solve(const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const {
    x = H.ldlt().solve(rhs);
    const double norm = rhs.norm();
    return {1, norm > 0.0 ? (H * x - rhs).norm() / norm : 0.0};
  }
};

}  // namespace bundletrack
