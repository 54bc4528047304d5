#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/rgbd_frame.hpp"

namespace bundletrack {

/// The camera of an image downsampled by `step` (grid pixel (x, y) is full-resolution pixel
/// (step x, step y)): fx' = fx / step, cx' = cx / step.
inline PinholeCameraf downsampledCamera(const PinholeCameraf& camera, int step) {
  const float s = 1.0f / float(step);
  return {camera.fx * s, camera.fy * s, camera.cx * s, camera.cy * s};
}

/// A frame's object surface on a downsampled grid, as the dense term (paper eq. 3), the pose
/// verification and the mask renderer read it: camera-frame points and unit normals, zero where
/// the frame has none (outside the mask, no depth, no normal); the cells that hold a point; and
/// the grid's own camera, so whoever projects into the grid needs nothing else.
struct SurfaceGrid {
  cv::Mat points;  ///< CV_32FC3
  cv::Mat normals;  ///< CV_32FC3
  std::vector<cv::Point> cells;  ///< grid cells with a point, row by row
  std::vector<cv::Vec3b> colors;  ///< BGR of each cell, in the order of `cells` (empty: no colour image)
  PinholeCameraf camera{};
  double noise_scale = 1.0;  ///< the sensor's NoiseScale at the points' median depth
  int step = 1;  ///< full-resolution pixels between neighbouring cells

  bool inside(int u, int v) const { return u >= 0 && v >= 0 && u < points.cols && v < points.rows; }
};

/// The grid step that samples about `target` of the points on `mask` with depth:
/// floor(sqrt(points / target)), at least 1 and at most max_step. An object's grids then hold a
/// similar number of points at any size and distance.
inline int gridStepFor(const RgbdFrame& frame, const cv::Mat& mask, int target, int max_step) {
  int points = 0;
  for (int v = 0; v < mask.rows; ++v)
    for (int u = 0; u < mask.cols; ++u) points += mask.at<uchar>(v, u) && frame.depth.at<float>(v, u) > 0.0f;
  const int step = int(std::floor(std::sqrt(double(points) / double(std::max(1, target)))));
  return std::clamp(step, 1, std::max(1, max_step));
}

/// Samples the masked surface of `frame` every `step` pixels. Only the cells inside the frame's
/// region are visited: outside it the frame has no points (makeFrame), so those cells stay zero.
inline SurfaceGrid sampleSurface(const RgbdFrame& frame, const cv::Mat& mask, const PinholeCameraf& camera, int step) {
  SurfaceGrid grid;
  grid.camera = downsampledCamera(camera, step);
  grid.step = step;
  const cv::Size size((frame.points.cols + step - 1) / step, (frame.points.rows + step - 1) / step);
  grid.points = cv::Mat::zeros(size, CV_32FC3);
  grid.normals = cv::Mat::zeros(size, CV_32FC3);
  const cv::Rect region = frame.region.area() > 0 ? frame.region : cv::Rect({0, 0}, frame.points.size());
  const auto firstCell = [step](int pixel) { return (pixel + step - 1) / step; };  // first cell at or after a pixel
  for (int y = firstCell(region.y); y < firstCell(region.br().y); ++y) {
    const int v = step * y;
    const auto* points = frame.points.ptr<cv::Vec3f>(v);
    const auto* normals = frame.normals.ptr<cv::Vec3f>(v);
    const uchar* on_object = mask.ptr<uchar>(v);
    for (int x = firstCell(region.x); x < firstCell(region.br().x); ++x) {
      const int u = step * x;
      if (!on_object[u] || points[u][2] <= 0.0f || normals[u][2] == 0.0f) continue;
      grid.points.at<cv::Vec3f>(y, x) = points[u];
      grid.normals.at<cv::Vec3f>(y, x) = normals[u];
      grid.cells.emplace_back(x, y);
      if (!frame.color.empty()) grid.colors.push_back(frame.color.at<cv::Vec3b>(v, u));
    }
  }
  std::vector<float> depths;
  for (const cv::Point& cell : grid.cells) depths.push_back(grid.points.at<cv::Vec3f>(cell)[2]);
  grid.noise_scale = frame.noise.atMedian(std::move(depths));
  return grid;
}

/// Lists the cells of a grid filled by hand (tests, synthetic data).
inline void indexCells(SurfaceGrid& grid) {
  grid.cells.clear();
  for (int y = 0; y < grid.points.rows; ++y)
    for (int x = 0; x < grid.points.cols; ++x)
      if (grid.points.at<cv::Vec3f>(y, x)[2] > 0.0f) grid.cells.emplace_back(x, y);
}

}  // namespace bundletrack
