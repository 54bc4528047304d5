#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace bundletrack {

/// Pixels beyond an object's mask (or search region) whose depth a tracker reads: the plane fits
/// of keypoints' normals (CropSettings::normal_radius, 3 px) around keypoints on the mask's rim.
inline constexpr int kRegionMargin = 8;

/// `box` grown by `margin` pixels on every side, within an image of size `image`.
inline cv::Rect grownWithin(const cv::Rect& box, int margin, cv::Size image) {
  return cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
         cv::Rect({0, 0}, image);
}

/// The bounding box of a mask's pixels; the whole image for an empty or all-zero mask.
inline cv::Rect maskBoxOrWhole(const cv::Mat& mask, cv::Size image) {
  const cv::Rect box = mask.empty() ? cv::Rect() : cv::boundingRect(mask);
  return box.area() > 0 ? box : cv::Rect({0, 0}, image);
}

/// The part of a frame a tracker with given masks reads when given `mask`: its box grown by
/// kRegionMargin (the whole image for an empty mask).
inline cv::Rect maskRegion(const cv::Mat& mask, cv::Size image) {
  return grownWithin(maskBoxOrWhole(mask, image), kRegionMargin, image);
}

}  // namespace bundletrack
