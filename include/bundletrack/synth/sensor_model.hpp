#pragma once

#include <cmath>
#include <random>

#include <opencv2/core.hpp>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/synth/renderer.hpp"

namespace bundletrack::synth {

/// A depth sensor and a colour camera: the depth noise of one of the library's presets
/// (DepthNoise: structured light by default, Kinect v1 measurements), dropouts at depth edges and
/// grazing angles, colour noise. Every effect can be switched off by zeroing its parameter.
struct SensorSettings {
  DepthNoise depth_noise = DepthNoise::structuredLight();
  double min_range = 0.2, max_range = 4.0;  ///< metres; outside: no reading
  double edge_jump = 0.01;  ///< metres; a 4-neighbour this much farther or closer marks a depth edge
  double edge_dropout = 0.6;  ///< probability that a depth-edge pixel has no reading
  double grazing_angle_deg = 78.0;  ///< no reading where the surface is seen more obliquely than this
  double random_dropout = 0.002;  ///< probability of a missing reading anywhere
  double color_noise = 2.0;  ///< grey levels, Gaussian per channel

  /// No noise, quantisation, dropouts or colour noise at all.
  static SensorSettings perfect() {
    SensorSettings s;
    s.depth_noise = DepthNoise();
    s.edge_dropout = s.random_dropout = s.color_noise = 0.0;
    s.grazing_angle_deg = 90.0;
    return s;
  }
};

/// Turns a clean render into a sensor reading: depth in metres (0 = no reading), BGR 8-bit.
/// Deterministic for a given seed.
inline void applySensorModel(const RenderBuffers& clean, const PinholeCamerad& camera, const SensorSettings& s,
                             unsigned seed, cv::Mat& depth, cv::Mat& color) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double cos_grazing = std::cos(radians(s.grazing_angle_deg));
  depth = cv::Mat(clean.depth.size(), CV_32FC1, cv::Scalar(0));
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const double noise = gauss(rng), dropout = uniform(rng);  // drawn for every pixel: stable streams
      const double z = clean.depth.at<float>(v, u);
      if (z <= s.min_range || z >= s.max_range || dropout < s.random_dropout) continue;
      bool edge = false;
      for (const auto& [dv, du] : {std::pair{0, 1}, {0, -1}, {1, 0}, {-1, 0}}) {
        const int vv = v + dv, uu = u + du;
        if (vv < 0 || uu < 0 || vv >= depth.rows || uu >= depth.cols) continue;
        const double zn = clean.depth.at<float>(vv, uu);
        edge |= zn <= 0.0 || std::abs(zn - z) > s.edge_jump;
      }
      if (edge && dropout < s.edge_dropout) continue;
      const cv::Vec3f& n = clean.normal.at<cv::Vec3f>(v, u);
      const Eigen::Vector3d ray = camera.unproject(u, v, 1.0).normalized();
      if (std::abs(ray.dot(Eigen::Vector3d(n[0], n[1], n[2]))) < cos_grazing) continue;
      depth.at<float>(v, u) = float(s.depth_noise.quantised(z + s.depth_noise.sigma(z, camera.fx) * noise, camera.fx));
    }
  }
  cv::Mat noisy = clean.color.clone();
  if (s.color_noise > 0.0) {
    cv::Mat noise(noisy.size(), CV_32FC3);
    cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, s.color_noise);
    noisy += noise;
  }
  noisy.convertTo(color, CV_8UC3);
}

}  // namespace bundletrack::synth
