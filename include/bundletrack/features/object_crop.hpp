#pragma once

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/disc_dilation.hpp"

namespace bundletrack {

/// The object's image region as the keypoint detector sees it (original code, paper IV-B): the
/// bounding box of the dilated mask, padded to a square and resized to size x size, so small
/// objects are upsampled. Maps crop pixels back to full-resolution pixels.
struct ObjectCrop {
  cv::Mat gray;  ///< CV_8UC1, size x size
  cv::Mat mask;  ///< CV_8UC1, 255 inside the dilated object mask
  double left = 0.0, top = 0.0;  ///< the square's top-left corner in full-resolution pixel-edge coordinates
  double scale = 1.0;  ///< crop pixels per full-resolution pixel

  /// Crop pixel centre (x, y) -> full-resolution (u, v), both with pixel centres at integers.
  cv::Point2f toImage(const cv::Point2f& p) const {
    return {float(left + (p.x + 0.5) / scale), float(top + (p.y + 0.5) / scale)};
  }
};

/// Returns an empty crop (gray.empty()) when the mask is empty.
inline ObjectCrop makeObjectCrop(const cv::Mat& bgr, const cv::Mat& mask, int size, int dilation_px) {
  ObjectCrop crop;
  const cv::Mat dilated = dilation_px > 0 ? dilatedByDisc(mask, dilation_px) : mask;
  const cv::Rect box = cv::boundingRect(dilated);
  if (box.area() == 0) return crop;
  const double side = std::max(box.width, box.height);
  crop.left = box.x - 0.5 + 0.5 * (box.width - side);
  crop.top = box.y - 0.5 + 0.5 * (box.height - side);
  crop.scale = size / side;
  // x_crop = scale (u - left) - 0.5 maps the square onto the crop with centres at integers.
  const cv::Matx23d warp(crop.scale, 0.0, -crop.scale * crop.left - 0.5, 0.0, crop.scale, -crop.scale * crop.top - 0.5);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  cv::warpAffine(gray, crop.gray, warp, {size, size}, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpAffine(dilated, crop.mask, warp, {size, size}, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  return crop;
}

}  // namespace bundletrack
