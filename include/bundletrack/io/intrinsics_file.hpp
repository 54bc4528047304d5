#pragma once

#include <cmath>
#include <filesystem>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/io/text_numbers.hpp"

namespace bundletrack::io {

/// The camera of cam_K.txt's numbers: the 3x3 matrix K = [fx 0 cx; 0 fy cy; 0 0 1], row by row.
inline PinholeCamerad intrinsicsFromNumbers(const std::vector<double>& k, const std::filesystem::path& path) {
  if (k.size() != 9) throw InputError(path, "expected 9 numbers (3x3 K), found " + std::to_string(k.size()));
  for (const double value : k)
    if (!std::isfinite(value)) throw InputError(path, "K has a non-finite entry");
  if (!(k[0] > 0.0) || !(k[4] > 0.0)) throw InputError(path, "focal lengths K[0][0] and K[1][1] must be positive");
  if (k[1] != 0.0 || k[3] != 0.0) throw InputError(path, "K has skew or shear terms; only a pinhole K is supported");
  if (k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) throw InputError(path, "last row of K must be 0 0 1");
  return {k[0], k[4], k[2], k[5]};
}

/// Reads cam_K.txt (intrinsicsFromNumbers).
inline PinholeCamerad readIntrinsics(const std::filesystem::path& path) {
  return intrinsicsFromNumbers(readNumbers(path), path);
}

}  // namespace bundletrack::io
