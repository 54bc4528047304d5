#pragma once

// A robust loss chosen at run time, for code that cannot be a template over the loss type (the
// CUDA kernels receive the loss as plain data). Evaluates the very loss structs of losses.hpp.

#include <type_traits>

#include "bundletrack/robust/losses.hpp"

namespace bundletrack {

enum class LossKind { Trivial, Huber, Cauchy, Tukey };

/// A loss as plain data: its kind and its one parameter (Huber's delta, Cauchy's and Tukey's scale).
struct LossParameters {
  LossKind kind = LossKind::Trivial;
  double parameter = 0.0;

  BUNDLETRACK_HOST_DEVICE LossValue evaluate(double s) const {
    switch (kind) {
      case LossKind::Huber: return HuberLoss{parameter}.evaluate(s);
      case LossKind::Cauchy: return CauchyLoss{parameter}.evaluate(s);
      case LossKind::Tukey: return TukeyLoss{parameter}.evaluate(s);
      case LossKind::Trivial: break;
    }
    return TrivialLoss{}.evaluate(s);
  }
};

template <RobustLoss Loss>
LossParameters lossParameters(const Loss& loss) {
  if constexpr (std::is_same_v<Loss, TrivialLoss>) return {LossKind::Trivial, 0.0};
  else if constexpr (std::is_same_v<Loss, HuberLoss>) return {LossKind::Huber, loss.delta};
  else if constexpr (std::is_same_v<Loss, CauchyLoss>) return {LossKind::Cauchy, loss.scale};
  else if constexpr (std::is_same_v<Loss, TukeyLoss>) return {LossKind::Tukey, loss.scale};
  else static_assert(!sizeof(Loss), "this robust loss has no run-time kind (Trivial, Huber, Cauchy, Tukey have)");
}

}  // namespace bundletrack
