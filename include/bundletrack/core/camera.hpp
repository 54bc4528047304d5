#pragma once

#include <Eigen/Core>

#include "bundletrack/core/macros.hpp"
#include "bundletrack/core/pixel.hpp"

namespace bundletrack {

/// Pinhole intrinsics without distortion. Pixels are (u, v) = (column, row) with pixel centres at
/// integer coordinates: u = fx x / z + cx, v = fy y / z + cy.
template <typename Scalar_>
struct PinholeCamera {
  using Scalar = Scalar_;
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  Scalar fx{}, fy{}, cx{}, cy{};

  BUNDLETRACK_HOST_DEVICE Vector2 project(const Vector3& p) const {
    return Vector2(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
  }

  /// The pixel (u, v) that camera-frame point p projects into (projectToPixel, in p's scalar
  /// type); false for a point on or behind the image plane.
  template <typename Derived>
  bool pixelOf(const Eigen::MatrixBase<Derived>& p, int& u, int& v) const {
    return projectToPixel(fx, fy, cx, cy, p.x(), p.y(), p.z(), u, v);
  }

  /// The camera-frame point seen at pixel (u, v) with depth z (metres along the optical axis).
  BUNDLETRACK_HOST_DEVICE Vector3 unproject(Scalar u, Scalar v, Scalar z) const {
    return Vector3((u - cx) * z / fx, (v - cy) * z / fy, z);
  }

  BUNDLETRACK_HOST_DEVICE Matrix3 matrix() const {
    Matrix3 K;
    K << fx, Scalar(0), cx, Scalar(0), fy, cy, Scalar(0), Scalar(0), Scalar(1);
    return K;
  }

  template <typename Other>
  BUNDLETRACK_HOST_DEVICE PinholeCamera<Other> cast() const {
    return {Other(fx), Other(fy), Other(cx), Other(cy)};
  }
};

using PinholeCameraf = PinholeCamera<float>;
using PinholeCamerad = PinholeCamera<double>;

}  // namespace bundletrack
