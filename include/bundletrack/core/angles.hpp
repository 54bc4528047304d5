#pragma once

// Degrees exist only at the user interface (configuration, reports); inside, angles are radians.

#include <cmath>
#include <concepts>
#include <numbers>

#include "bundletrack/core/macros.hpp"

namespace bundletrack {

template <std::floating_point T>
BUNDLETRACK_HOST_DEVICE constexpr T radians(T degrees) {
  return degrees * std::numbers::pi_v<T> / T(180);
}

template <std::floating_point T>
BUNDLETRACK_HOST_DEVICE constexpr T degrees(T radians) {
  return radians * T(180) / std::numbers::pi_v<T>;
}

/// The cosine of an angle given in degrees, computed in T: gates compare dot products of unit
/// normals with it.
template <std::floating_point T>
T cosOfDegrees(float degrees_value) {
  return std::cos(radians(T(degrees_value)));
}

}  // namespace bundletrack
