#pragma once

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/bilinear.hpp"
#include "bundletrack/core/surface_grid.hpp"

namespace bundletrack {

/// A frame's brightness on the object, as the photometric term reads it: the grey image lightly
/// smoothed (so that its derivatives are the scene's, not the sensor's pixel noise) less its local
/// mean over the object (a Gaussian of `kLocalMeanSigma` over object pixels only), and the
/// derivatives along u and v, over `box` (full-resolution pixels). Taking the local mean away keeps
/// the texture and drops the slow brightness change that shading under a light fixed to the camera
/// (or the world) paints on a turning object; it is defined `valid` only where the smoothing and
/// the derivatives see object pixels alone, so the background never enters.
struct IntensityImage {
  static constexpr double kLocalMeanSigma = 3.0;  ///< pixels
  cv::Mat samples;  ///< CV_32FC3, box.size(): intensity and its derivatives along u and v, side by side
  cv::Mat valid;  ///< CV_8UC1, box.size(): non-zero where intensity and derivatives are defined
  cv::Rect box;
  /// A cell of the keyframe's surface grid (its index in SurfaceGrid::cells) where the image is
  /// defined, with the intensity there: what the photometric term reads of its source frame.
  struct CellIntensity {
    int cell;
    float intensity;
  };
  std::vector<CellIntensity> cells;  ///< in the grid's cell order (sampleCells)

  bool empty() const { return samples.empty(); }

  /// Bilinear intensity and derivatives at full-resolution pixel (u, v) (centres at integers);
  /// false where the four neighbours are not all valid.
  bool sample(double u, double v, double& value, double& du, double& dv) const {
    return sampleBilinear(samples, box, valid, u, v, value, du, dv);
  }

  /// Fills `cells` from the grid's cells (full-resolution pixel step x cell), where the image is
  /// defined. The sample sits on a pixel centre, so it is that pixel's intensity.
  void sampleCells(const SurfaceGrid& grid) {
    cells.clear();
    if (empty()) return;
    for (std::size_t k = 0; k < grid.cells.size(); ++k) {
      double value = 0.0, du = 0.0, dv = 0.0;
      if (sample(grid.step * grid.cells[k].x, grid.step * grid.cells[k].y, value, du, dv))
        cells.push_back({int(k), float(value)});
    }
  }
};

/// The intensity image of `bgr` on `mask`, over the mask's bounding box grown by `margin` pixels
/// (empty without a colour image or a mask pixel). Smoothing: a 3x3 Gaussian (sigma 0.8 px);
/// derivatives: the 3x3 Sobel operator over 8, in intensity (0-1) per pixel; valid: the mask eroded
/// by the two 3x3 stencils.
inline IntensityImage makeIntensityImage(const cv::Mat& bgr, const cv::Mat& mask, int margin) {
  IntensityImage image;
  if (bgr.empty() || mask.empty()) return image;
  const cv::Rect object = cv::boundingRect(mask);
  if (object.area() == 0) return image;
  image.box = cv::Rect(object.x - margin, object.y - margin, object.width + 2 * margin, object.height + 2 * margin) &
              cv::Rect({0, 0}, bgr.size());
  cv::Mat gray, smooth, on_object, weighted, coverage;
  cv::cvtColor(bgr(image.box), gray, cv::COLOR_BGR2GRAY);
  gray.convertTo(gray, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(gray, smooth, {3, 3}, 0.8, 0.8, cv::BORDER_REPLICATE);
  mask(image.box).convertTo(on_object, CV_32F, 1.0 / 255.0);
  const double s = IntensityImage::kLocalMeanSigma;
  const cv::Size window(2 * int(std::ceil(3 * s)) + 1, 2 * int(std::ceil(3 * s)) + 1);
  cv::GaussianBlur(smooth.mul(on_object), weighted, window, s, s, cv::BORDER_CONSTANT);
  cv::GaussianBlur(on_object, coverage, window, s, s, cv::BORDER_CONSTANT);
  const cv::Mat intensity = smooth - weighted / cv::max(coverage, 1e-6);
  cv::Mat d_u, d_v;
  cv::Sobel(intensity, d_u, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(intensity, d_v, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::merge(std::vector<cv::Mat>{intensity, d_u, d_v}, image.samples);
  cv::erode(mask(image.box), image.valid, cv::Mat(), {-1, -1}, 2, cv::BORDER_CONSTANT, cv::Scalar(0));
  return image;
}

}  // namespace bundletrack
