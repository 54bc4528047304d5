#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace bundletrack::synth {

/// Multi-scale colour noise: octaves of random colours at 4, 8, ... cells per side, each
/// upsampled bicubically and weighted by half the previous octave.
inline cv::Mat noiseTexture(int size, unsigned seed, double contrast = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  cv::Mat sum(size, size, CV_32FC3, cv::Scalar::all(0));
  float amplitude = 1.0f;
  for (int cells = 4; cells <= size / 4; cells *= 2, amplitude *= 0.6f) {
    cv::Mat coarse(cells, cells, CV_32FC3);
    for (auto it = coarse.begin<cv::Vec3f>(); it != coarse.end<cv::Vec3f>(); ++it)
      *it = cv::Vec3f(uniform(rng), uniform(rng), uniform(rng)) * amplitude;
    cv::Mat fine;
    cv::resize(coarse, fine, {size, size}, 0, 0, cv::INTER_CUBIC);
    sum += fine;
  }
  cv::Mat texture;
  sum.convertTo(texture, CV_8UC3, 60.0 * contrast, 128.0);
  return texture;
}

/// Rich texture for keypoints: noise, then filled shapes and printed words in random colours,
/// like the print on a product package.
inline cv::Mat richTexture(int size, unsigned seed) {
  cv::Mat texture = noiseTexture(size, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_int_distribution<int> coord(0, size - 1), extent(size / 40, size / 8), channel(0, 255);
  const auto colour = [&] { return cv::Scalar(channel(rng), channel(rng), channel(rng)); };
  for (int i = 0; i < 40; ++i) {
    const cv::Point p(coord(rng), coord(rng));
    switch (i % 4) {
      case 0: cv::circle(texture, p, extent(rng), colour(), cv::FILLED, cv::LINE_AA); break;
      case 1: cv::rectangle(texture, cv::Rect(p, cv::Size(extent(rng), extent(rng))), colour(), cv::FILLED); break;
      case 2: cv::line(texture, p, cv::Point(coord(rng), coord(rng)), colour(), 1 + size / 200, cv::LINE_AA); break;
      default: cv::ellipse(texture, p, {extent(rng), extent(rng) / 2}, coord(rng) % 180, 0, 360, colour(), 3, cv::LINE_AA);
    }
  }
  static const char* const kWords[] = {"BundleTrack", "RGB-D", "NET WT 400g", "ORGANIC", "No. 42", "SE(3)",
                                       "KEEP DRY", "Lot 7A-19", "PCG", "Made in Lab"};
  for (int i = 0; i < 24; ++i) {
    const double scale = size / 600.0 * (0.6 + 0.15 * (i % 6));
    cv::putText(texture, kWords[(seed + unsigned(i)) % 10], cv::Point(coord(rng), coord(rng)), cv::FONT_HERSHEY_DUPLEX,
                scale, colour(), std::max(1, int(2 * scale)), cv::LINE_AA);
  }
  return texture;
}

/// One flat colour: the "nearly textureless" case (only shading varies on the surface).
inline cv::Mat plainTexture(const cv::Scalar& bgr) { return cv::Mat(8, 8, CV_8UC3, bgr); }

/// Bilinear lookup at (u, v), texture coordinates in [0, 1]^2 (u along columns, v along rows).
/// Outside the square the texture repeats mirrored, so tiled planes show no seams.
inline cv::Vec3f sampleTexture(const cv::Mat& texture, double u, double v) {
  const auto mirror = [](double t) {
    const double m = t - 2.0 * std::floor(0.5 * t);  // in [0, 2)
    return m > 1.0 ? 2.0 - m : m;
  };
  const double x = mirror(u) * texture.cols - 0.5, y = mirror(v) * texture.rows - 0.5;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = float(x - x0), fy = float(y - y0);
  const auto at = [&](int xx, int yy) {
    return cv::Vec3f(texture.at<cv::Vec3b>(std::clamp(yy, 0, texture.rows - 1), std::clamp(xx, 0, texture.cols - 1)));
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

}  // namespace bundletrack::synth
