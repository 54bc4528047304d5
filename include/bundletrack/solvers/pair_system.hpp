#pragma once

#include <Eigen/Core>

#include "bundletrack/robust/losses.hpp"

namespace bundletrack {

/// The weighted normal equations of one edge over the stacked right perturbations [d_i; d_j]:
/// H += J^T W J, b += J^T W r, cost += rho, summed over the edge's residuals.
struct PairSystem {
  Eigen::Matrix<double, 12, 12> H = Eigen::Matrix<double, 12, 12>::Zero();
  Eigen::Matrix<double, 12, 1> b = Eigen::Matrix<double, 12, 1>::Zero();
  double cost = 0.0;
  int residuals = 0;

  /// Adds an N-dimensional residual r with Jacobians J_i, J_j (N x 6), robustly weighted by `loss`
  /// and scaled by `weight` (lambda in paper eq. 1).
  template <int N, typename Loss>
  void add(const Eigen::Matrix<double, N, 1>& r, const Eigen::Matrix<double, N, 6>& J_i,
           const Eigen::Matrix<double, N, 6>& J_j, const Loss& loss, double weight) {
    const LossValue l = loss.evaluate(r.squaredNorm());
    Eigen::Matrix<double, N, 12> J;
    J.template leftCols<6>() = J_i;
    J.template rightCols<6>() = J_j;
    const double w = weight * l.d_rho;
    H.noalias() += w * J.transpose() * J;
    b.noalias() += w * J.transpose() * r;
    cost += weight * l.rho;
    ++residuals;
  }

  /// Adds a scalar residual that depends on the relative pose only, so that dr/dd_j = -dr/dd_i:
  /// one 6x6 outer product serves all four blocks (H_ii = H_jj = -H_ij = w J^T J).
  template <typename Loss>
  void addRelative(double r, const Eigen::Matrix<double, 1, 6>& J_i, const Loss& loss, double weight) {
    const LossValue l = loss.evaluate(r * r);
    const double w = weight * l.d_rho;
    const Eigen::Matrix<double, 1, 6> wJ = w * J_i;
    for (int c = 0; c < 6; ++c)  // the lower triangle; finish() mirrors it
      for (int k = c; k < 6; ++k) relative_H_(k, c) += wJ(k) * J_i(c);
    relative_b_.noalias() += (w * r) * J_i.transpose();
    cost += weight * l.rho;
    ++residuals;
  }

  /// Adds the sums of many addRelative() calls at once: sum w J_i^T J_i (its lower triangle is
  /// read), sum w r J_i^T, the weighted losses and their count (a GPU backend accumulates these on
  /// the device).
  void addRelativeSums(const Eigen::Matrix<double, 6, 6>& JtWJ, const Eigen::Matrix<double, 6, 1>& JtWr, double cost_sum,
                       int count) {
    relative_H_ += JtWJ;
    relative_b_ += JtWr;
    cost += cost_sum;
    residuals += count;
  }

  /// Folds the relative-pose accumulators into H and b; call once after the last addRelative().
  void finish() {
    for (int c = 1; c < 6; ++c)
      for (int k = 0; k < c; ++k) relative_H_(k, c) = relative_H_(c, k);
    H.topLeftCorner<6, 6>() += relative_H_;
    H.bottomRightCorner<6, 6>() += relative_H_;
    H.topRightCorner<6, 6>() -= relative_H_;
    H.bottomLeftCorner<6, 6>() -= relative_H_;
    b.head<6>() += relative_b_;
    b.tail<6>() -= relative_b_;
    relative_H_.setZero();
    relative_b_.setZero();
  }

 private:
  Eigen::Matrix<double, 6, 6> relative_H_ = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> relative_b_ = Eigen::Matrix<double, 6, 1>::Zero();
};

}  // namespace bundletrack
