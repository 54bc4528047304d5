#pragma once

#include <cmath>
#include <concepts>

#include "bundletrack/core/macros.hpp"

namespace bundletrack {

/// A robust loss rho(s) of the squared residual norm s = |r|^2 (the Ceres contract): evaluate(s)
/// gives rho(s), rho'(s) and rho''(s). Gauss-Newton weights every residual by rho'(s) in both
/// J^T W J and J^T W r (the original code weighted only J^T r for the feature term). Each loss is
/// one body for the host and the CUDA kernels.
struct LossValue {
  double rho, d_rho, dd_rho;
};

template <typename T>
concept RobustLoss = requires(const T& loss, double s) {
  { loss.evaluate(s) } -> std::same_as<LossValue>;
};

/// The least a RobustLoss offers; concepts check with it that a policy accepts any loss, not
/// one in particular. Never evaluated.
struct RobustLossArchetype {
  LossValue evaluate(double s) const;
};

/// Plain least squares: rho(s) = s.
struct TrivialLoss {
  BUNDLETRACK_HOST_DEVICE LossValue evaluate(double s) const { return {s, 1.0, 0.0}; }
};

/// Huber: quadratic up to |r| = delta, linear beyond. rho(s) = s for s <= delta^2, else
/// 2 delta sqrt(s) - delta^2. Paper IV-D; delta = 5 mm as the original code.
struct HuberLoss {
  double delta = 0.005;
  BUNDLETRACK_HOST_DEVICE LossValue evaluate(double s) const {
    if (s <= delta * delta) return {s, 1.0, 0.0};
    const double r = std::sqrt(s);
    return {2.0 * delta * r - delta * delta, delta / r, -0.5 * delta / (s * r)};
  }
};

/// Cauchy: rho(s) = c^2 log(1 + s / c^2).
struct CauchyLoss {
  double scale = 0.005;
  BUNDLETRACK_HOST_DEVICE LossValue evaluate(double s) const {
    const double c2 = scale * scale, q = 1.0 + s / c2;
    return {c2 * std::log(q), 1.0 / q, -1.0 / (c2 * q * q)};
  }
};

/// Tukey's biweight: rho(s) = c^2 / 3 (1 - (1 - s / c^2)^3) for s <= c^2, constant beyond, so
/// residuals larger than c get no weight at all.
struct TukeyLoss {
  double scale = 0.01;
  BUNDLETRACK_HOST_DEVICE LossValue evaluate(double s) const {
    const double c2 = scale * scale;
    if (s > c2) return {c2 / 3.0, 0.0, 0.0};
    const double q = 1.0 - s / c2;
    return {c2 / 3.0 * (1.0 - q * q * q), q * q, -2.0 * q / c2};
  }
};

}  // namespace bundletrack
