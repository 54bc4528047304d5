#pragma once

#include <cmath>

#include <opencv2/core.hpp>

namespace bundletrack {

/// Bilinear value and derivatives at full-resolution pixel (u, v) (centres at integers) of a
/// CV_32FC3 image of (value, d/du, d/dv) that covers `box` of the full image; false where one of
/// the four neighbours lies outside the box or, when `valid` (CV_8UC1, box.size()) is given, is
/// not valid.
inline bool sampleBilinear(const cv::Mat& samples, const cv::Rect& box, const cv::Mat& valid, double u, double v,
                           double& value, double& du, double& dv) {
  const double x = u - box.x, y = v - box.y;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= box.width || y0 + 1 >= box.height) return false;
  if (!valid.empty()) {
    const uchar* m0 = valid.ptr<uchar>(y0) + x0;
    const uchar* m1 = valid.ptr<uchar>(y0 + 1) + x0;
    if (!(m0[0] && m0[1] && m1[0] && m1[1])) return false;
  }
  const double a = x - x0, b = y - y0;
  const cv::Vec3f* r0 = samples.ptr<cv::Vec3f>(y0) + x0;
  const cv::Vec3f* r1 = samples.ptr<cv::Vec3f>(y0 + 1) + x0;
  const auto mix = [&](int c) { return (1 - b) * ((1 - a) * r0[0][c] + a * r0[1][c]) + b * ((1 - a) * r1[0][c] + a * r1[1][c]); };
  value = mix(0), du = mix(1), dv = mix(2);
  return true;
}

}  // namespace bundletrack
