#include "bundletrack/cuda/pcg.hpp"

#include <mutex>
#include <vector>

#include "pcg_device.hpp"
#include "pcg_host.hpp"

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
  const Eigen::Index n = H.rows();
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  w.H.resize(std::size_t(n * n));
  Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(w.H.data(), n, n) = H.cast<float>();
  detail::blockJacobiInverse(H, damping, w.block_inverse);
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
