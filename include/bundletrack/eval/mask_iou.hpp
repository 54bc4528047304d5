#pragma once

#include <opencv2/core.hpp>

#include "bundletrack/core/error.hpp"

namespace bundletrack {

/// Intersection over union of two CV_8UC1 masks (nonzero = object); 1 when both are empty.
inline double maskIoU(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != CV_8UC1 || b.type() != CV_8UC1)
    throw InputError("maskIoU", "masks must be CV_8UC1 of one size");
  const int both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either == 0 ? 1.0 : double(both) / double(either);
}

}  // namespace bundletrack
