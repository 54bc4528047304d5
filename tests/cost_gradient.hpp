#pragma once

#include <Eigen/Core>

#include "bundletrack/core/se3.hpp"

/// Central differences of an edge's cost with respect to the stacked right perturbations
/// [d_i; d_j] of its two poses, halved: with the trivial loss (cost = sum r^2) this is the
/// gradient of 1/2 sum r^2, which a residual's b = J^T r must equal.
template <typename Cost>
Eigen::Matrix<double, 12, 1> halfCostGradient(Cost&& cost, const bundletrack::SE3d& T_i, const bundletrack::SE3d& T_j,
                                              double h) {
  using bundletrack::SE3d;
  Eigen::Matrix<double, 12, 1> gradient;
  for (int k = 0; k < 12; ++k) {
    SE3d::Tangent d = SE3d::Tangent::Zero();
    d[k % 6] = h;
    const bool first = k < 6;
    const double plus = cost(first ? T_i * SE3d::exp(d) : T_i, first ? T_j : T_j * SE3d::exp(d));
    const double minus = cost(first ? T_i * SE3d::exp(-d) : T_i, first ? T_j : T_j * SE3d::exp(-d));
    gradient[k] = (plus - minus) / (2 * h) / 2.0;
  }
  return gradient;
}
