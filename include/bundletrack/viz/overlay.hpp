#pragma once

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/core/object_box.hpp"

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

/// Draws the posed object box's 12 edges; edges with an end behind the camera are skipped.
inline void drawBox(cv::Mat& bgr, const PinholeCamerad& camera, const SE3d& T_cam_obj, const ObjectBox& box,
                    const cv::Scalar& colour, int thickness = 1) {
  const auto corners = box.corners();
  for (int a = 0; a < 8; ++a) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      const int b = a | bit;
      if (b == a) continue;
      const Eigen::Vector3d pa = T_cam_obj * corners[std::size_t(a)], pb = T_cam_obj * corners[std::size_t(b)];
      if (pa.z() <= 0.0 || pb.z() <= 0.0) continue;
      const Eigen::Vector2d ua = camera.project(pa), ub = camera.project(pb);
      cv::line(bgr, cv::Point2d(ua.x(), ua.y()), cv::Point2d(ub.x(), ub.y()), colour, thickness, cv::LINE_AA);
    }
  }
}

/// A line plot of one or two series over frames (e.g. rotation error in degrees and translation
/// error in cm), each scaled to its own maximum, with the maxima printed in the series' colour.
inline cv::Mat plotSeries(const std::vector<double>& a, const std::string& a_label, const std::vector<double>& b,
                          const std::string& b_label, cv::Size size = {900, 360}) {
  cv::Mat plot(size, CV_8UC3, cv::Scalar::all(255));
  const int left = 60, right = 20, top = 40, bottom = 40;
  const cv::Rect area(left, top, size.width - left - right, size.height - top - bottom);
  cv::rectangle(plot, area, cv::Scalar::all(0));
  const auto draw = [&](const std::vector<double>& v, const std::string& label, const cv::Scalar& colour, int row) {
    if (v.empty()) return;
    double peak = 1e-9;
    for (const double x : v) peak = std::max(peak, x);
    std::vector<cv::Point> line;
    for (std::size_t i = 0; i < v.size(); ++i)
      line.emplace_back(area.x + int(double(i) / std::max<std::size_t>(1, v.size() - 1) * area.width),
                        area.y + area.height - int(v[i] / peak * area.height));
    cv::polylines(plot, line, false, colour, 2, cv::LINE_AA);
    char text[128];
    std::snprintf(text, sizeof(text), "%s (max %.2f)", label.c_str(), peak);
    cv::putText(plot, text, {left + 10 + 400 * row, 25}, cv::FONT_HERSHEY_SIMPLEX, 0.6, colour, 1, cv::LINE_AA);
  };
  draw(a, a_label, {40, 40, 220}, 0);
  draw(b, b_label, {200, 90, 20}, 1);
  cv::putText(plot, "frame", {size.width / 2 - 20, size.height - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(0));
  return plot;
}

}  // namespace bundletrack::viz
