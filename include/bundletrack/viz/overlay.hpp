#pragma once

#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack::viz {

/// Draws the object frame's axes (x red, y green, z blue, `length` metres) at pose T_cam_obj.
/// Axes behind the camera are skipped.
inline void drawAxes(cv::Mat& bgr, const PinholeCamerad& camera, const SE3d& T_cam_obj, double length,
                     int thickness = 2) {
  const Eigen::Vector3d origin = T_cam_obj.translation();
  if (origin.z() <= 0.0) return;
  const auto pixel = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d uv = camera.project(p);
    return cv::Point2d(uv.x(), uv.y());
  };
  const cv::Scalar colours[3] = {{0, 0, 255}, {0, 200, 0}, {255, 0, 0}};
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d tip = T_cam_obj * Eigen::Vector3d(length * Eigen::Vector3d::Unit(axis));
    if (tip.z() <= 0.0) continue;
    cv::line(bgr, pixel(origin), pixel(tip), colours[axis], thickness, cv::LINE_AA);
  }
}

/// Outlines a binary mask in `colour`.
inline void drawMaskContour(cv::Mat& bgr, const cv::Mat& mask, const cv::Scalar& colour, int thickness = 1) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(bgr, contours, -1, colour, thickness, cv::LINE_AA);
}

}  // namespace bundletrack::viz
