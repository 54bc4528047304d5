#pragma once

#include <memory>
#include <span>
#include <type_traits>

#include "bundletrack/residuals/pair_system.hpp"

namespace bundletrack::cuda {

/// The robust losses the GPU kernels evaluate, as plain data across the boundary.
struct LossParameters {
  enum Kind { Trivial, Huber, Cauchy, Tukey } kind = Trivial;
  double parameter = 0.0;  ///< Huber's delta, Cauchy's and Tukey's scale
};

template <RobustLoss Loss>
LossParameters lossParameters(const Loss& loss) {
  if constexpr (std::is_same_v<Loss, TrivialLoss>) return {LossParameters::Trivial, 0.0};
  else if constexpr (std::is_same_v<Loss, HuberLoss>) return {LossParameters::Huber, loss.delta};
  else if constexpr (std::is_same_v<Loss, CauchyLoss>) return {LossParameters::Cauchy, loss.scale};
  else if constexpr (std::is_same_v<Loss, TukeyLoss>) return {LossParameters::Tukey, loss.scale};
  else static_assert(!sizeof(Loss), "this robust loss has no GPU version (Trivial, Huber, Cauchy, Tukey have)");
}

/// The dense point-to-plane term (paper eq. 3) on the GPU: the association, gates, residual and
/// Jacobian of bundletrack::DensePointToPlane, robust weights and each edge's normal equations
/// accumulated in double on the device. lineariseAll() does every direction of every edge of a
/// graph in one kernel launch (Energy and Gauss-Newton call it once per iteration). Keyframe grids
/// are uploaded once and stay on the device while they are in use (the 64 most recently used).
/// Satisfies BatchResidual, so Energy<..., Term<cuda::DensePointToPlane, HuberLoss>> composes.
class DensePointToPlane {
 public:
  float max_distance = 0.02f;  ///< metres (original code: 2 cm)
  float max_normal_angle_deg = 45.0f;

  DensePointToPlane();

  template <RobustLoss Loss>
  void linearise(const PairInput& in, const Loss& loss, double weight, PairSystem& system) const {
    lineariseAllWith(std::span(&in, 1), lossParameters(loss), weight, std::span(&system, 1));
  }

  /// systems[e] += the residuals of edge inputs[e], for all edges in one launch.
  template <RobustLoss Loss>
  void lineariseAll(std::span<const PairInput> inputs, const Loss& loss, double weight,
                    std::span<PairSystem> systems) const {
    lineariseAllWith(inputs, lossParameters(loss), weight, systems);
  }

 private:
  void lineariseAllWith(std::span<const PairInput> inputs, const LossParameters& loss, double weight,
                        std::span<PairSystem> systems) const;

  struct Workspace;
  std::shared_ptr<Workspace> workspace_;
};

}  // namespace bundletrack::cuda
