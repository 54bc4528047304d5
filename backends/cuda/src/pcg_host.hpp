#pragma once

// What the host hands the PCG kernel: the block-Jacobi preconditioner as float 6x6 blocks.

#include <vector>

#include <Eigen/Cholesky>

namespace bundletrack::cuda::detail {

/// The inverses of H's damped 6x6 diagonal blocks, row-major, as bundletrack::PCG builds them
/// (damping times the block's mean diagonal; a block that does not factor gives its inverted
/// diagonal), factored in double and stored in float.
inline void blockJacobiInverse(const Eigen::MatrixXd& H, double damping, std::vector<float>& out) {
  const Eigen::Index blocks = H.rows() / 6;
  out.resize(std::size_t(36 * blocks));
  for (Eigen::Index k = 0; k < blocks; ++k) {
    Eigen::Matrix<double, 6, 6> block = H.block<6, 6>(6 * k, 6 * k);
    const double mean_diagonal = block.diagonal().mean();
    block.diagonal().array() += damping * (mean_diagonal > 0.0 ? mean_diagonal : 1.0);
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(block);
    const Eigen::Matrix<double, 6, 6> inverse =
        llt.info() == Eigen::Success ? Eigen::Matrix<double, 6, 6>(llt.solve(Eigen::Matrix<double, 6, 6>::Identity()))
                                     : Eigen::Matrix<double, 6, 6>(block.diagonal().cwiseMax(1e-12).cwiseInverse().asDiagonal());
    Eigen::Map<Eigen::Matrix<float, 6, 6, Eigen::RowMajor>>(out.data() + 36 * k) = inverse.cast<float>();
  }
}

}  // namespace bundletrack::cuda::detail
