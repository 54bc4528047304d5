#pragma once

#include "bundletrack/core/so3.hpp"

namespace bundletrack {

/// Rigid transforms T = (R, t), p' = R p + t. Conventions (docs/DESIGN.md section 2): T_a_b maps frame b
/// into frame a; tangent vectors are ordered [v; w] (translation, then rotation); updates are right
/// perturbations T <- T * exp(d). Jacobians are named after what they differentiate.
template <typename Scalar_>
class SE3 {
 public:
  using Scalar = Scalar_;
  using Rotation = SO3<Scalar>;
  using Tangent = Eigen::Matrix<Scalar, 6, 1>;
  using Point = Eigen::Matrix<Scalar, 3, 1>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Matrix4 = Eigen::Matrix<Scalar, 4, 4>;
  using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;
  using Matrix3x6 = Eigen::Matrix<Scalar, 3, 6>;

  BUNDLETRACK_HOST_DEVICE SE3() : rotation_(), translation_(Vector3::Zero()) {}
  BUNDLETRACK_HOST_DEVICE SE3(const Rotation& R, const Vector3& t) : rotation_(R), translation_(t) {}

  /// From a homogeneous 4x4 matrix whose top-left block is a rotation.
  BUNDLETRACK_HOST_DEVICE static SE3 fromMatrix(const Matrix4& T) {
    return SE3(Rotation::fromMatrix(T.template topLeftCorner<3, 3>()), T.template topRightCorner<3, 1>());
  }

  /// hat([v; w]) = [[w]x v; 0 0].
  BUNDLETRACK_HOST_DEVICE static Matrix4 hat(const Tangent& xi) {
    Matrix4 X = Matrix4::Zero();
    X.template topLeftCorner<3, 3>() = Rotation::hat(xi.template tail<3>());
    X.template topRightCorner<3, 1>() = xi.template head<3>();
    return X;
  }

  BUNDLETRACK_HOST_DEVICE static Tangent vee(const Matrix4& X) {
    Tangent xi;
    xi.template head<3>() = X.template topRightCorner<3, 1>();
    xi.template tail<3>() = Rotation::vee(X.template topLeftCorner<3, 3>());
    return xi;
  }

  /// exp([v; w]) = (exp(w), J_l(w) v), with J_l the left Jacobian of SO(3).
  BUNDLETRACK_HOST_DEVICE static SE3 exp(const Tangent& xi) {
    const Vector3 w = xi.template tail<3>();
    return SE3(Rotation::exp(w), Rotation::leftJacobian(w) * xi.template head<3>());
  }

  BUNDLETRACK_HOST_DEVICE Tangent log() const {
    const Vector3 w = rotation_.log();
    Tangent xi;
    xi.template head<3>() = Rotation::leftJacobianInverse(w) * translation_;
    xi.template tail<3>() = w;
    return xi;
  }

  BUNDLETRACK_HOST_DEVICE SE3 inverse() const {
    const Rotation R_inv = rotation_.inverse();
    return SE3(R_inv, -(R_inv * translation_));
  }

  BUNDLETRACK_HOST_DEVICE SE3 operator*(const SE3& other) const {
    return SE3(rotation_ * other.rotation_, rotation_ * other.translation_ + translation_);
  }

  BUNDLETRACK_HOST_DEVICE Point operator*(const Point& p) const { return rotation_ * p + translation_; }

  /// Adj(T) = [[R, [t]x R]; [0, R]], so that T exp(d) T^-1 = exp(Adj(T) d).
  BUNDLETRACK_HOST_DEVICE Matrix6 adjoint() const {
    const Matrix3 R = rotation_.matrix();
    Matrix6 A = Matrix6::Zero();
    A.template topLeftCorner<3, 3>() = R;
    A.template topRightCorner<3, 3>() = Rotation::hat(translation_) * R;
    A.template bottomRightCorner<3, 3>() = R;
    return A;
  }

  BUNDLETRACK_HOST_DEVICE Matrix4 matrix() const {
    Matrix4 T = Matrix4::Identity();
    T.template topLeftCorner<3, 3>() = rotation_.matrix();
    T.template topRightCorner<3, 1>() = translation_;
    return T;
  }

  BUNDLETRACK_HOST_DEVICE const Rotation& rotation() const { return rotation_; }
  BUNDLETRACK_HOST_DEVICE const Vector3& translation() const { return translation_; }
  BUNDLETRACK_HOST_DEVICE Matrix3 rotationMatrix() const { return rotation_.matrix(); }

  template <typename Other>
  BUNDLETRACK_HOST_DEVICE SE3<Other> cast() const {
    return SE3<Other>(rotation_.template cast<Other>(), translation_.template cast<Other>());
  }

  /// d(T exp(d) p)/dd at d = 0: R [I, -[p]x]. The Jacobian of a transformed point in the
  /// Gauss-Newton steps of the pose graph (paper eq. 2 and 3).
  BUNDLETRACK_HOST_DEVICE Matrix3x6 J_action_delta(const Point& p) const {
    const Matrix3 R = rotation_.matrix();
    Matrix3x6 J;
    J.template leftCols<3>() = R;
    J.template rightCols<3>() = -R * Rotation::hat(p);
    return J;
  }

  /// d((T exp(d))^-1 p)/dd at d = 0: [-I, [q]x] with q = T^-1 p. Paper eq. 2 moves camera points
  /// into the object frame with T_i^-1.
  BUNDLETRACK_HOST_DEVICE Matrix3x6 J_inverseAction_delta(const Point& p) const {
    const Point q = inverse() * p;
    Matrix3x6 J;
    J.template leftCols<3>() = -Matrix3::Identity();
    J.template rightCols<3>() = Rotation::hat(q);
    return J;
  }

  /// Left Jacobian of exp on SE(3): [[J_l(w), Q(v, w)]; [0, J_l(w)]] (Barfoot, State Estimation
  /// for Robotics, eq. 7.85-7.86), exp(xi + d) ~= exp(J_l(xi) d) exp(xi).
  BUNDLETRACK_HOST_DEVICE static Matrix6 leftJacobian(const Tangent& xi) {
    const Matrix3 J = Rotation::leftJacobian(xi.template tail<3>());
    Matrix6 out = Matrix6::Zero();
    out.template topLeftCorner<3, 3>() = J;
    out.template topRightCorner<3, 3>() = translationCoupling(xi);
    out.template bottomRightCorner<3, 3>() = J;
    return out;
  }

  /// Inverse of the block-triangular left Jacobian: [[J^-1, -J^-1 Q J^-1]; [0, J^-1]].
  BUNDLETRACK_HOST_DEVICE static Matrix6 leftJacobianInverse(const Tangent& xi) {
    const Matrix3 J_inv = Rotation::leftJacobianInverse(xi.template tail<3>());
    Matrix6 out = Matrix6::Zero();
    out.template topLeftCorner<3, 3>() = J_inv;
    out.template topRightCorner<3, 3>() = -J_inv * translationCoupling(xi) * J_inv;
    out.template bottomRightCorner<3, 3>() = J_inv;
    return out;
  }

  /// Right Jacobian: exp(xi + d) ~= exp(xi) exp(J_r(xi) d), with J_r(xi) = J_l(-xi).
  BUNDLETRACK_HOST_DEVICE static Matrix6 rightJacobian(const Tangent& xi) { return leftJacobian(-xi); }
  BUNDLETRACK_HOST_DEVICE static Matrix6 rightJacobianInverse(const Tangent& xi) { return leftJacobianInverse(-xi); }

 private:
  /// Barfoot's Q(v, w), the top-right block of the SE(3) left Jacobian.
  BUNDLETRACK_HOST_DEVICE static Matrix3 translationCoupling(const Tangent& xi) {
    const Matrix3 V = Rotation::hat(xi.template head<3>());
    const Matrix3 W = Rotation::hat(xi.template tail<3>());
    const Scalar theta_sq = xi.template tail<3>().squaredNorm();
    Scalar c1, c2, c3;
    if (std::sqrt(theta_sq) < kSmallAngle<Scalar>) {
      c1 = Scalar(1) / Scalar(6) - theta_sq / Scalar(120) + theta_sq * theta_sq / Scalar(5040);
      c2 = Scalar(1) / Scalar(24) - theta_sq / Scalar(720) + theta_sq * theta_sq / Scalar(40320);
      c3 = Scalar(1) / Scalar(120) - theta_sq / Scalar(2520) + theta_sq * theta_sq / Scalar(120960);
    } else {
      const Scalar theta = std::sqrt(theta_sq);
      const Scalar s = std::sin(theta), c = std::cos(theta);
      c1 = (theta - s) / (theta_sq * theta);
      c2 = (theta_sq + Scalar(2) * c - Scalar(2)) / (Scalar(2) * theta_sq * theta_sq);
      c3 = (Scalar(2) * theta - Scalar(3) * s + theta * c) / (Scalar(2) * theta_sq * theta_sq * theta);
    }
    const Matrix3 WV = W * V, VW = V * W, WVW = WV * W;
    return Scalar(0.5) * V + c1 * (WV + VW + WVW) + c2 * (W * WV + VW * W - Scalar(3) * WVW) +
           c3 * (WVW * W + W * WVW);
  }

  Rotation rotation_;
  Vector3 translation_;
};

using SE3f = SE3<float>;
using SE3d = SE3<double>;

}  // namespace bundletrack
