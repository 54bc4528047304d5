#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

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
/// the grid's own camera, so whoever projects into the grid needs nothing else. Grid cell (x, y)
/// is full-resolution pixel (step x, step y); the images hold only the box of the cells with a
/// point (`origin` is the cell of their first element), so a small object costs its own size,
/// not the image's (a 640x480 grid at step 1 is 7.4 MB). Read them through point(), normal() and
/// inside(), which take grid cells.
struct SurfaceGrid {
  cv::Mat points;  ///< CV_32FC3, the box of the cells from `origin`
  cv::Mat normals;  ///< CV_32FC3, the same box
  cv::Point origin{0, 0};  ///< the grid cell of points(0, 0)
  std::vector<cv::Point> cells;  ///< grid cells with a point, row by row
  std::vector<cv::Vec3b> colors;  ///< BGR of each cell, in the order of `cells` (empty: no colour image)
  PinholeCameraf camera{};
  double noise_scale = 1.0;  ///< the sensor's NoiseScale at the points' median depth
  int step = 1;  ///< full-resolution pixels between neighbouring cells

  bool inside(int x, int y) const {
    return x >= origin.x && y >= origin.y && x - origin.x < points.cols && y - origin.y < points.rows;
  }
  /// The point and normal of a cell inside() the grid.
  const cv::Vec3f& point(int x, int y) const { return points.at<cv::Vec3f>(y - origin.y, x - origin.x); }
  const cv::Vec3f& normal(int x, int y) const { return normals.at<cv::Vec3f>(y - origin.y, x - origin.x); }
  const cv::Vec3f& point(cv::Point cell) const { return point(cell.x, cell.y); }
  const cv::Vec3f& normal(cv::Point cell) const { return normal(cell.x, cell.y); }
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
/// region are visited: outside it the frame has no points (makeFrame).
inline SurfaceGrid sampleSurface(const RgbdFrame& frame, const cv::Mat& mask, const PinholeCameraf& camera, int step) {
  SurfaceGrid grid;
  grid.camera = downsampledCamera(camera, step);
  grid.step = step;
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
      grid.cells.emplace_back(x, y);
      if (!frame.color.empty()) grid.colors.push_back(frame.color.at<cv::Vec3b>(v, u));
    }
  }
  const cv::Rect box = grid.cells.empty() ? cv::Rect(0, 0, 1, 1) : cv::boundingRect(grid.cells);  // no point: one empty cell
  grid.origin = box.tl();
  grid.points = cv::Mat::zeros(box.size(), CV_32FC3);
  grid.normals = cv::Mat::zeros(box.size(), CV_32FC3);
  std::vector<float> depths;
  depths.reserve(grid.cells.size());
  for (const cv::Point& cell : grid.cells) {
    const cv::Point pixel = step * cell, local = cell - grid.origin;
    grid.points.at<cv::Vec3f>(local) = frame.points.at<cv::Vec3f>(pixel);
    grid.normals.at<cv::Vec3f>(local) = frame.normals.at<cv::Vec3f>(pixel);
    depths.push_back(frame.points.at<cv::Vec3f>(pixel)[2]);
  }
  grid.noise_scale = frame.noise.atMedian(std::move(depths));
  return grid;
}

/// Lists the cells of a grid filled by hand (tests, synthetic data).
inline void indexCells(SurfaceGrid& grid) {
  grid.cells.clear();
  for (int y = 0; y < grid.points.rows; ++y)
    for (int x = 0; x < grid.points.cols; ++x)
      if (grid.points.at<cv::Vec3f>(y, x)[2] > 0.0f) grid.cells.push_back(grid.origin + cv::Point(x, y));
}

}  // namespace bundletrack
