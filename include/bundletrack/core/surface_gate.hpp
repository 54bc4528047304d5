#pragma once

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/depth_noise.hpp"

namespace bundletrack {

/// When two oriented points count as the same surface point: within max_distance of each other
/// and with normals within max_normal_angle_deg. The defaults are the original code's gate for
/// pairs of frames whose relative pose is known (docs/DESIGN.md section 3: 2 cm, 45 degrees), used by
/// the edge matches (paper IV-D) and the dense term's association (paper eq. 3).
struct SurfaceGate {
  float max_distance = 0.02f;  ///< metres
  float max_normal_angle_deg = 45.0f;

  /// The gate as squared distance and cosine bounds, in T.
  template <typename T>
  struct Bounds {
    T max_squared_distance, cos_max_angle;
    bool admits(T squared_distance, T cos_angle) const {
      return squared_distance <= max_squared_distance && cos_angle >= cos_max_angle;
    }
  };

  /// The gate between readings `scale` times noisier than the reference ones (NoiseScale): the
  /// distance widened, the angle kept.
  SurfaceGate widened(double scale) const { return {float(max_distance * scale), max_normal_angle_deg}; }

  template <typename T>
  Bounds<T> bounds() const {
    return {T(max_distance) * T(max_distance), cosOfDegrees<T>(max_normal_angle_deg)};
  }
};

}  // namespace bundletrack
