#pragma once

#include <memory>

#include <Eigen/Core>

#include "bundletrack/solvers/linear_solver.hpp"

namespace bundletrack::cuda {

/// True when a CUDA device is present and usable (tests skip otherwise).
bool deviceAvailable();

/// The PCG policy on the GPU: the same algorithm as bundletrack::PCG (block-Jacobi preconditioner
/// of the damped 6x6 diagonal blocks, residual stopping test), in float, one kernel launch per
/// solve. Device buffers persist across solves and only grow. Satisfies LinearSolver, so
/// Tracker<Energy, cuda::PCG, ...> composes. No CUDA type appears in this header.
class PCG {
 public:
  int max_iterations = 5;
  double tolerance = 1e-6;  ///< relative residual; float arithmetic cannot go much below 1e-6
  double damping = 1e-9;

  PCG();
  SolveReport solve(const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const;

 private:
  struct Workspace;
  std::shared_ptr<Workspace> workspace_;
};

}  // namespace bundletrack::cuda
