#pragma once

#include <Eigen/Cholesky>

namespace bundletrack {

/// The block-Jacobi preconditioner of PCG (paper IV-D): the inverse of each node's 6x6 diagonal
/// block of H, damped by `damping` times the block's mean diagonal before the factorisation (as
/// Ceres does); a block that still fails to factor gives its inverted diagonal. Calls
/// store(k, inverse) for each block k. The GPU PCG stores the same inverses in float.
template <typename Store>
void blockJacobiInverse(const Eigen::MatrixXd& H, double damping, Store&& store) {
  const Eigen::Index blocks = H.rows() / 6;
  for (Eigen::Index k = 0; k < blocks; ++k) {
    Eigen::Matrix<double, 6, 6> block = H.block<6, 6>(6 * k, 6 * k);
    const double mean_diagonal = block.diagonal().mean();
    block.diagonal().array() += damping * (mean_diagonal > 0.0 ? mean_diagonal : 1.0);
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(block);
    if (llt.info() == Eigen::Success) {
      store(k, Eigen::Matrix<double, 6, 6>(llt.solve(Eigen::Matrix<double, 6, 6>::Identity())));
    } else {
      store(k, Eigen::Matrix<double, 6, 6>(block.diagonal().cwiseMax(1e-12).cwiseInverse().asDiagonal()));
    }
  }
}

}  // namespace bundletrack
