#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "bundletrack/core/macros.hpp"

namespace bundletrack {

/// Below this rotation angle (radians) the closed forms switch to their Taylor series; the series
/// keep terms up to theta^4, so the truncation error is O(theta^6), far below the type's epsilon.
template <typename Scalar>
inline constexpr Scalar kSmallAngle = sizeof(Scalar) <= 4 ? Scalar(3e-2) : Scalar(1e-3);

/// Rotations in 3-D, stored as a unit quaternion. The tangent is the rotation vector w (axis times
/// angle); exp(w) = I + sin|w|/|w| [w]x + (1 - cos|w|)/|w|^2 [w]x^2 (Rodrigues).
template <typename Scalar_>
class SO3 {
 public:
  using Scalar = Scalar_;
  using Tangent = Eigen::Matrix<Scalar, 3, 1>;
  using Point = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Quaternion = Eigen::Quaternion<Scalar>;

  BUNDLETRACK_HOST_DEVICE SO3() : q_(Quaternion::Identity()) {}
  BUNDLETRACK_HOST_DEVICE explicit SO3(const Quaternion& q) : q_(q.normalized()) {}

  /// From a rotation matrix (assumed orthonormal with det +1; the quaternion is renormalised).
  BUNDLETRACK_HOST_DEVICE static SO3 fromMatrix(const Matrix3& R) { return SO3(Quaternion(R)); }

  BUNDLETRACK_HOST_DEVICE static Matrix3 hat(const Tangent& w) {
    Matrix3 W;
    W << Scalar(0), -w.z(), w.y(),  //
        w.z(), Scalar(0), -w.x(),   //
        -w.y(), w.x(), Scalar(0);
    return W;
  }

  BUNDLETRACK_HOST_DEVICE static Tangent vee(const Matrix3& W) { return Tangent(W(2, 1), W(0, 2), W(1, 0)); }

  BUNDLETRACK_HOST_DEVICE static SO3 exp(const Tangent& w) {
    const Scalar theta_sq = w.squaredNorm();
    const Scalar theta = std::sqrt(theta_sq);
    Scalar real, imag;  // q = (cos(theta/2), sin(theta/2)/theta * w)
    if (theta < kSmallAngle<Scalar>) {
      real = Scalar(1) - theta_sq / Scalar(8) + theta_sq * theta_sq / Scalar(384);
      imag = Scalar(0.5) - theta_sq / Scalar(48) + theta_sq * theta_sq / Scalar(3840);
    } else {
      real = std::cos(theta / Scalar(2));
      imag = std::sin(theta / Scalar(2)) / theta;
    }
    return SO3(Quaternion(real, imag * w.x(), imag * w.y(), imag * w.z()));
  }

  /// The rotation vector with angle in [0, pi]; stable near 0 and near pi (atan2 form).
  BUNDLETRACK_HOST_DEVICE Tangent log() const {
    const Scalar sign = q_.w() < Scalar(0) ? Scalar(-1) : Scalar(1);
    const Scalar real = sign * q_.w();
    const Tangent imag = sign * q_.vec();
    const Scalar imag_norm = imag.norm();
    if (imag_norm < kSmallAngle<Scalar> * real) {
      // 2 atan(n / r) / n = (2 / r) (1 - n^2 / (3 r^2) + ...)
      const Scalar ratio_sq = imag_norm * imag_norm / (real * real);
      return (Scalar(2) / real) * (Scalar(1) - ratio_sq / Scalar(3) + ratio_sq * ratio_sq / Scalar(5)) * imag;
    }
    return (Scalar(2) * std::atan2(imag_norm, real) / imag_norm) * imag;
  }

  /// Rotation angle in [0, pi].
  BUNDLETRACK_HOST_DEVICE Scalar angle() const {
    return Scalar(2) * std::atan2(q_.vec().norm(), std::abs(q_.w()));
  }

  BUNDLETRACK_HOST_DEVICE SO3 inverse() const { return SO3(q_.conjugate()); }
  BUNDLETRACK_HOST_DEVICE SO3 operator*(const SO3& other) const { return SO3(q_ * other.q_); }
  BUNDLETRACK_HOST_DEVICE Point operator*(const Point& p) const { return q_ * p; }
  BUNDLETRACK_HOST_DEVICE Matrix3 matrix() const { return q_.toRotationMatrix(); }
  /// Adj(R) = R: R exp(w) R^T = exp(R w).
  BUNDLETRACK_HOST_DEVICE Matrix3 adjoint() const { return matrix(); }
  BUNDLETRACK_HOST_DEVICE const Quaternion& unitQuaternion() const { return q_; }

  template <typename Other>
  BUNDLETRACK_HOST_DEVICE SO3<Other> cast() const {
    return SO3<Other>(q_.template cast<Other>());
  }

  /// Left Jacobian: exp(w + d) ~= exp(J_l(w) d) exp(w).
  /// J_l = I + (1 - cos t)/t^2 [w]x + (t - sin t)/t^3 [w]x^2.
  BUNDLETRACK_HOST_DEVICE static Matrix3 leftJacobian(const Tangent& w) {
    const Scalar theta_sq = w.squaredNorm();
    Scalar a, b;
    if (std::sqrt(theta_sq) < kSmallAngle<Scalar>) {
      a = Scalar(0.5) - theta_sq / Scalar(24) + theta_sq * theta_sq / Scalar(720);
      b = Scalar(1) / Scalar(6) - theta_sq / Scalar(120) + theta_sq * theta_sq / Scalar(5040);
    } else {
      const Scalar theta = std::sqrt(theta_sq);
      a = (Scalar(1) - std::cos(theta)) / theta_sq;
      b = (theta - std::sin(theta)) / (theta_sq * theta);
    }
    const Matrix3 W = hat(w);
    return Matrix3::Identity() + a * W + b * W * W;
  }

  /// Inverse of the left Jacobian: I - [w]x / 2 + (1/t^2 - cot(t/2) / (2t)) [w]x^2.
  /// The cot form stays finite at t = pi, where (1 + cos t) / sin t would divide 0 by 0.
  BUNDLETRACK_HOST_DEVICE static Matrix3 leftJacobianInverse(const Tangent& w) {
    const Scalar theta_sq = w.squaredNorm();
    Scalar c;
    if (std::sqrt(theta_sq) < kSmallAngle<Scalar>) {
      c = Scalar(1) / Scalar(12) + theta_sq / Scalar(720) + theta_sq * theta_sq / Scalar(30240);
    } else {
      const Scalar theta = std::sqrt(theta_sq);
      const Scalar half = theta / Scalar(2);
      c = Scalar(1) / theta_sq - std::cos(half) / (Scalar(2) * theta * std::sin(half));
    }
    const Matrix3 W = hat(w);
    return Matrix3::Identity() - Scalar(0.5) * W + c * W * W;
  }

  /// Right Jacobian: exp(w + d) ~= exp(w) exp(J_r(w) d), with J_r(w) = J_l(-w).
  BUNDLETRACK_HOST_DEVICE static Matrix3 rightJacobian(const Tangent& w) { return leftJacobian(-w); }
  BUNDLETRACK_HOST_DEVICE static Matrix3 rightJacobianInverse(const Tangent& w) { return leftJacobianInverse(-w); }

 private:
  Quaternion q_;
};

/// Geodesic distance between two rotations, arccos((tr(Ra^T Rb) - 1) / 2), in radians: the edge
/// weight of the keyframe selection (paper section IV-C).
template <typename Scalar>
BUNDLETRACK_HOST_DEVICE Scalar rotationGeodesic(const SO3<Scalar>& a, const SO3<Scalar>& b) {
  return (a.inverse() * b).angle();
}

using SO3f = SO3<float>;
using SO3d = SO3<double>;

}  // namespace bundletrack
