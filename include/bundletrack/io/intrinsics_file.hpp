#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "bundletrack/core/angles.hpp"
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

/// K must fit the images (of `size`; `source` names K in the error): RGB-D cameras see 40-120
/// degrees across (Kinect v1 57, RealSense D435 69-87, Azure Kinect 75-120), so a field of view
/// outside 10-170 degrees, or pixels more than twice as tall as wide (fx / fy), is a K for
/// another image size or in other units.
inline void checkFieldOfView(const PinholeCamerad& camera, cv::Size size, const std::filesystem::path& source) {
  const auto view = [](double pixels, double focal) { return degrees(2.0 * std::atan(0.5 * pixels / focal)); };
  const double across = view(size.width, camera.fx), down = view(size.height, camera.fy);
  const std::string stated = "fx " + std::to_string(camera.fx) + " px, fy " + std::to_string(camera.fy) +
                             " px give a field of view of " + std::to_string(across) + " x " + std::to_string(down) +
                             " degrees for the " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                             " images";
  if (std::min(across, down) < 10.0 || std::max(across, down) > 170.0)
    throw InputError(source, stated + "; RGB-D cameras see 40-120 degrees: is K for another image size or in other units?");
  const double aspect = camera.fx / camera.fy;
  if (aspect < 0.5 || aspect > 2.0)
    throw InputError(source, stated + ": fx / fy = " + std::to_string(aspect) + ", pixels far from square: is K mistyped?");
}

/// Reads cam_K.txt (intrinsicsFromNumbers).
inline PinholeCamerad readIntrinsics(const std::filesystem::path& path) {
  return intrinsicsFromNumbers(readNumbers(path), path);
}

}  // namespace bundletrack::io
