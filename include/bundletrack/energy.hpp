#pragma once

#include <tuple>

#include "bundletrack/residuals/pair_system.hpp"

namespace bundletrack {

/// One weighted term of the pose-graph energy (paper eq. 1): a residual, its robust loss and lambda.
template <Residual ResidualT, RobustLoss LossT>
struct Term {
  using ResidualType = ResidualT;
  using LossType = LossT;
  ResidualT residual{};
  LossT loss{};
  double weight = 1.0;
};

/// The energy as a compile-time list of terms, e.g.
///   Energy<Term<FeaturePointToPoint, HuberLoss>, Term<DensePointToPlane, HuberLoss>>
/// A feature-only tracker simply leaves the dense term out.
template <typename... Terms>
struct Energy {
  std::tuple<Terms...> terms;

  void linearise(const PairInput& input, PairSystem& system) const {
    std::apply([&](const auto&... term) { (term.residual.linearise(input, term.loss, term.weight, system), ...); },
               terms);
  }
};

template <typename T>
concept PoseGraphEnergy = requires(const T& energy, const PairInput& input, PairSystem& system) {
  { energy.linearise(input, system) } -> std::same_as<void>;
};

}  // namespace bundletrack
