#pragma once

#include <algorithm>
#include <cmath>
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

/// Axis ticks for values in [0, peak]: a step of 1, 2 or 5 times a power of ten giving at most
/// `most` intervals, and the axis' end, the first multiple of the step at or above peak.
struct Ticks {
  double step, end;
};
inline Ticks niceTicks(double peak, int most = 5) {
  if (!(peak > 0.0) || !std::isfinite(peak)) return {1.0, 1.0};
  const double raw = peak / most, power = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10.0 * power;
  for (const double m : {1.0, 2.0, 5.0})
    if (m * power >= raw * (1.0 - 1e-9)) {
      step = m * power;
      break;
    }
  return {step, step * std::ceil(peak / step - 1e-9)};
}

/// One labelled series of a plot over frames.
struct Series {
  std::string title;  ///< with its unit, e.g. "rotation error [deg]"
  std::vector<double> values;  ///< per frame; NaN: no value (drawn as a gap)
};

/// Errors over a sequence as a person reads them: one panel per series stacked over a shared frame
/// axis, each with its own y axis from 0 (ticks labelled in the series' unit, grid lines), its
/// title with mean and maximum, frame numbers on the x axis, and the frames in `lost` (true:
/// lost) shaded grey, named in the legend.
inline cv::Mat plotErrors(const std::vector<Series>& series, const std::vector<bool>& lost = {}, int width = 900,
                          int panel_height = 220) {
  const int left = 70, right = 20, top = 34, bottom = 46, gap = 40;
  const int count = int(series.size());
  cv::Mat plot(top + count * panel_height + (count - 1) * gap + bottom, width, CV_8UC3, cv::Scalar::all(255));
  std::size_t frames = 0;
  for (const Series& s : series) frames = std::max(frames, s.values.size());
  if (frames == 0) return plot;
  const int plot_width = width - left - right;
  const auto x_of = [&](double frame) { return left + int(std::lround(frame / double(std::max<std::size_t>(1, frames - 1)) * plot_width)); };
  const cv::Scalar ink = cv::Scalar::all(0), grid = cv::Scalar::all(225), shade = cv::Scalar::all(200);
  const auto text = [&](const std::string& t, cv::Point at, double scale, const cv::Scalar& colour) {
    cv::putText(plot, t, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
  };
  const auto label = [](double value, double step) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.*f", std::max(0, int(std::ceil(-std::log10(step) - 1e-9))), value);
    return std::string(buffer);
  };
  const Ticks frame_ticks = niceTicks(double(frames - 1), 10);
  const cv::Scalar colours[] = {{40, 40, 220}, {200, 90, 20}, {40, 150, 40}};
  for (int k = 0; k < count; ++k) {
    const Series& s = series[std::size_t(k)];
    const cv::Rect area(left, top + k * (panel_height + gap), plot_width, panel_height);
    for (std::size_t i = 0; i < lost.size() && i < frames; ++i)  // lost frames: a grey band each
      if (lost[i]) cv::rectangle(plot, cv::Rect(x_of(double(i)) - 1, area.y, std::max(2, plot_width / int(frames)), area.height), shade, cv::FILLED);
    double peak = 0.0, sum = 0.0;
    int present = 0;
    for (const double v : s.values)
      if (std::isfinite(v)) peak = std::max(peak, v), sum += v, ++present;
    const Ticks ticks = niceTicks(peak);
    for (double y = 0.0; y <= ticks.end * (1.0 + 1e-9); y += ticks.step) {
      const int row = area.y + area.height - int(std::lround(y / ticks.end * area.height));
      cv::line(plot, {area.x, row}, {area.x + area.width, row}, grid);
      const std::string t = label(y, ticks.step);
      text(t, {area.x - 8 - 9 * int(t.size()), row + 5}, 0.45, ink);
    }
    for (double f = 0.0; f <= double(frames - 1) + 1e-9; f += frame_ticks.step) {
      cv::line(plot, {x_of(f), area.y + area.height}, {x_of(f), area.y + area.height + 5}, ink);
      if (k == count - 1) text(label(f, 1.0), {x_of(f) - 10, area.y + area.height + 20}, 0.45, ink);
    }
    std::vector<cv::Point> line;
    const auto flush = [&] {
      if (line.size() > 1) cv::polylines(plot, line, false, colours[k % 3], 2, cv::LINE_AA);
      line.clear();
    };
    for (std::size_t i = 0; i < s.values.size(); ++i) {
      if (!std::isfinite(s.values[i])) {
        flush();
        continue;
      }
      line.emplace_back(x_of(double(i)), area.y + area.height - int(std::lround(s.values[i] / ticks.end * area.height)));
    }
    flush();
    cv::rectangle(plot, area, ink);
    char title[160];
    std::snprintf(title, sizeof(title), "%s   mean %.2f, max %.2f", s.title.c_str(), present ? sum / present : 0.0, peak);
    text(title, {area.x, area.y - 10}, 0.55, colours[k % 3]);
  }
  text("frame", {left + plot_width / 2 - 20, plot.rows - 8}, 0.5, ink);
  if (std::find(lost.begin(), lost.end(), true) != lost.end()) {
    cv::rectangle(plot, cv::Rect(width - right - 120, plot.rows - 22, 14, 12), shade, cv::FILLED);
    text("lost frames", {width - right - 100, plot.rows - 12}, 0.45, ink);
  }
  return plot;
}

}  // namespace bundletrack::viz
