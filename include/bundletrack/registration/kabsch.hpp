#pragma once

#include <vector>

#include <Eigen/SVD>

#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// Least-squares rigid transform T minimising sum_k ||T a_k - b_k||^2 (Arun, Huang, Blostein 1987;
/// Umeyama 1991 without scale): R = V diag(1, 1, det(V U^T)) U^T from the SVD U S V^T of the
/// cross-covariance; the determinant term turns a reflection into the nearest rotation.
/// `pair_at(k)` returns the k-th of `count` pairs (a, b). Needs three non-collinear pairs.
template <typename PairAt>
SE3d kabsch(std::size_t count, PairAt&& pair_at) {
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero(), mean_b = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    const auto [a, b] = pair_at(k);
    mean_a += a.template cast<double>();
    mean_b += b.template cast<double>();
  }
  mean_a /= double(count);
  mean_b /= double(count);
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    const auto [a, b] = pair_at(k);
    H += (a.template cast<double>() - mean_a) * (b.template cast<double>() - mean_b).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  return SE3d(SO3d::fromMatrix(R), mean_b - R * mean_a);
}

/// Convenience overload for two equally long point lists.
template <typename Point>
SE3d kabsch(const std::vector<Point>& a, const std::vector<Point>& b) {
  return kabsch(a.size(), [&](std::size_t k) { return std::pair<const Point&, const Point&>(a[k], b[k]); });
}

}  // namespace bundletrack
