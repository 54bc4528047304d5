#pragma once

// Pinhole projection to a pixel, in plain arithmetic for the host and CUDA kernels alike
// (pixel centres at integer coordinates, docs/DESIGN.md section 2).

#include <cmath>

#include "bundletrack/core/macros.hpp"

namespace bundletrack {

/// The pixel a continuous image coordinate falls in: rounded half away from zero, as std::lround,
/// in inline arithmetic (the dense terms round millions of projections per frame, and the library
/// call was 7 % of the tracker's time): truncation, then one step where the fraction is a half or
/// more (x - trunc(x) is exact). Coordinates beyond 1e9 in magnitude, far outside any image, and
/// NaN give -2e9, which every bounds check rejects.
template <typename T>
BUNDLETRACK_HOST_DEVICE int roundToPixel(T x) {
  if (!(x > T(-1e9) && x < T(1e9))) return -2000000000;
  const int truncated = int(x);
  const T fraction = x - T(truncated);
  return truncated + int(fraction >= T(0.5)) - int(fraction <= T(-0.5));
}

/// The pixel (u, v) that camera-frame point (x, y, z) projects into, u = fx x / z + cx and
/// v = fy y / z + cy computed in T; false (u, v untouched) for a point on or behind the image
/// plane. Bounds are the caller's to check.
template <typename C, typename T>
BUNDLETRACK_HOST_DEVICE bool projectToPixel(C fx, C fy, C cx, C cy, T x, T y, T z, int& u, int& v) {
  if (!(z > T(0))) return false;
  u = roundToPixel(T(fx) * x / z + T(cx));
  v = roundToPixel(T(fy) * y / z + T(cy));
  return true;
}

}  // namespace bundletrack
