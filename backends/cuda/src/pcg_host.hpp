#pragma once

// What the host hands the PCG kernel: the block-Jacobi preconditioner as float 6x6 blocks.

#include <vector>

#include "bundletrack/solvers/block_jacobi.hpp"

namespace bundletrack::cuda::detail {

/// The block-Jacobi inverses of bundletrack::PCG (blockJacobiInverse), row-major, in float.
inline void blockJacobiInverse(const Eigen::MatrixXd& H, double damping, std::vector<float>& out) {
  out.resize(std::size_t(36 * (H.rows() / 6)));
  bundletrack::blockJacobiInverse(H, damping, [&](Eigen::Index k, const Eigen::Matrix<double, 6, 6>& inverse) {
    Eigen::Map<Eigen::Matrix<float, 6, 6, Eigen::RowMajor>>(out.data() + 36 * k) = inverse.cast<float>();
  });
}

}  // namespace bundletrack::cuda::detail
