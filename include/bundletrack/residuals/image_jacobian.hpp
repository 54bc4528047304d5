#pragma once

#include <Eigen/Core>

namespace bundletrack {

/// An image's derivatives (d_u, d_v) per pixel at the projection of camera-frame point q, pulled
/// back through the pinhole projection with full-resolution focal lengths (fx, fy):
///   g = (dpi/dq)^T grad,
/// the change of the image's value per metre that q moves.
inline Eigen::Vector3d imageGradientAt(const Eigen::Vector3d& q, double fx, double fy, double d_u, double d_v) {
  const double iz = 1.0 / q.z();
  return {d_u * fx * iz, d_v * fy * iz, -(d_u * fx * q.x() + d_v * fy * q.y()) * iz * iz};
}

/// The Jacobian of a residual read from an image of frame t at the projection of an object point a,
/// seen at q = T_t a where the image's pulled-back gradient is g (imageGradientAt), for a right
/// perturbation of T_t:
///   dr/dd_t = [w^T, (a x w)^T],  w = R_t^T g.
/// A residual that depends on the relative pose only has dr/dd_s = -dr/dd_t.
inline Eigen::Matrix<double, 1, 6> imageResidualJacobian(const Eigen::Vector3d& g, const Eigen::Vector3d& a,
                                                         const Eigen::Matrix3d& R_t) {
  const Eigen::Vector3d w = R_t.transpose() * g;
  Eigen::Matrix<double, 1, 6> J_t;
  J_t.leftCols<3>() = w.transpose();
  J_t.rightCols<3>() = a.cross(w).transpose();
  return J_t;
}

}  // namespace bundletrack
