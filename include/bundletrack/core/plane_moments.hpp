#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace bundletrack {

/// The first and second moments of a point set, for a least-squares plane through it: the plane
/// passes through the mean, and its normal is the covariance's eigenvector of least eigenvalue.
struct PlaneMoments {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  int count = 0;

  void add(const Eigen::Vector3d& p) {
    sum += p;
    second += p * p.transpose();
    ++count;
  }

  /// Requires count > 0.
  Eigen::Vector3d mean() const { return sum / count; }

  /// The unit normal of the least-squares plane, of either sign; requires count > 0.
  Eigen::Vector3d normal() const {
    const Eigen::Vector3d m = mean();
    const Eigen::Matrix3d covariance = second / count - m * m.transpose();
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvectors().col(0);
  }
};

}  // namespace bundletrack
