#include "bundletrack/cuda/pcg.hpp"

#include <mutex>
#include <vector>

#include <Eigen/Cholesky>

#include "pcg_device.hpp"

namespace bundletrack::cuda {

struct PCG::Workspace {
  std::mutex mutex;  // one solve at a time uses the device buffers
  detail::DeviceBuffers* buffers = detail::createBuffers();
  std::vector<float> H, block_inverse, rhs, x;
  ~Workspace() { detail::destroyBuffers(buffers); }
};

bool deviceAvailable() { return detail::deviceAvailable(); }

PCG::PCG() : workspace_(std::make_shared<Workspace>()) {}

SolveReport PCG::solve(const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const {
  const Eigen::Index n = H.rows(), blocks = n / 6;
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  w.H.resize(std::size_t(n * n));
  Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(w.H.data(), n, n) = H.cast<float>();
  // Preconditioner blocks as in bundletrack::PCG, factored on the host in double (36 numbers each).
  w.block_inverse.resize(std::size_t(36 * blocks));
  for (Eigen::Index k = 0; k < blocks; ++k) {
    Eigen::Matrix<double, 6, 6> block = H.block<6, 6>(6 * k, 6 * k);
    const double mean_diagonal = block.diagonal().mean();
    block.diagonal().array() += damping * (mean_diagonal > 0.0 ? mean_diagonal : 1.0);
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(block);
    const Eigen::Matrix<double, 6, 6> inverse =
        llt.info() == Eigen::Success ? Eigen::Matrix<double, 6, 6>(llt.solve(Eigen::Matrix<double, 6, 6>::Identity()))
                                     : Eigen::Matrix<double, 6, 6>(block.diagonal().cwiseMax(1e-12).cwiseInverse().asDiagonal());
    Eigen::Map<Eigen::Matrix<float, 6, 6, Eigen::RowMajor>>(w.block_inverse.data() + 36 * k) = inverse.cast<float>();
  }
  w.rhs.resize(std::size_t(n));
  for (Eigen::Index i = 0; i < n; ++i) w.rhs[std::size_t(i)] = float(rhs[i]);
  w.x.resize(std::size_t(n));
  float residual = 0.0f;
  const int iterations = detail::solvePcg(*w.buffers, w.H.data(), w.block_inverse.data(), w.rhs.data(), w.x.data(),
                                          int(n), max_iterations, float(tolerance), &residual);
  x = Eigen::Map<const Eigen::VectorXf>(w.x.data(), n).cast<double>();
  return {iterations, double(residual)};
}

}  // namespace bundletrack::cuda
