#pragma once

#include <cmath>
#include <limits>
#include <random>

#include <opencv2/core.hpp>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/synth/renderer.hpp"

namespace bundletrack::synth {

/// A depth sensor and a colour camera: the depth noise of one of the library's presets
/// (DepthNoise: structured light by default, Kinect v1 measurements), the shadow a triangulating
/// sensor's second viewpoint leaves beside near surfaces, dropouts at depth edges and grazing
/// angles, colour noise. Every effect can be switched off (its parameter zero, `shadow` false).
struct SensorSettings {
  DepthNoise depth_noise = DepthNoise::structuredLight();
  /// The shadow of a triangulating sensor (one whose noise has a disparity term: structured light,
  /// active stereo): the viewpoint it also needs to see a point from lies depth_noise.baseline
  /// along the camera's +x -- the projector of a structured-light camera (Kinect v1: 7.5 cm), the
  /// second imager of an active-stereo one (D435: 5 cm; depth in the left imager's frame) -- and
  /// a surface hidden from there has no reading: a band beside the left side of a near object on
  /// the surface behind it (shadowedPixels). Time of flight, lit from beside its lens, has none.
  bool shadow = true;
  double min_range = 0.2, max_range = 4.0;  ///< metres; outside: no reading
  double edge_jump = 0.01;  ///< metres; a 4-neighbour this much farther or closer marks a depth edge
  double edge_dropout = 0.6;  ///< probability that a depth-edge pixel has no reading
  /// Probability that a depth-edge pixel with a reading reads a mix of the two surfaces it spans,
  /// z + a (z_n - z) with a uniform in [0, 1) and z_n its 4-neighbour farthest in depth: the flying
  /// pixels of a time-of-flight camera, whose pixel integrates light from both (0: none).
  double flying_pixels = 0.0;
  double grazing_angle_deg = 78.0;  ///< no reading where the surface is seen more obliquely than this
  double random_dropout = 0.002;  ///< probability of a missing reading anywhere
  double color_noise = 2.0;  ///< grey levels, Gaussian per channel

  /// No noise, quantisation, dropouts or colour noise at all.
  static SensorSettings perfect() {
    SensorSettings s;
    s.depth_noise = DepthNoise();
    s.edge_dropout = s.random_dropout = s.color_noise = 0.0;
    s.shadow = false;
    s.grazing_angle_deg = 90.0;
    return s;
  }
};

/// Whether a sensor with this noise triangulates (its noise has a disparity term), and so casts
/// a shadow (SensorSettings::shadow).
inline bool triangulates(const DepthNoise& noise) { return noise.subpixel > 0.0 || noise.disparity_step > 0.0; }

/// Pixels the second viewpoint of a triangulating sensor (`baseline` metres along the camera's
/// +x, focal length `fx`) cannot see in a depth image (CV_32FC1, metres, 0: nothing there), as a
/// mask: seen from there, pixel u of depth z lies at u - fx baseline / z, and a pixel is hidden
/// where a pixel to its right, nearer, lands at or left of it (one pass per row from the right,
/// keeping the leftmost landing). A step from z_near to z_far leaves a band of
/// fx baseline (1 / z_near - 1 / z_far) pixels.
inline cv::Mat shadowedPixels(const cv::Mat& depth, double fx, double baseline) {
  cv::Mat shadowed(depth.size(), CV_8UC1, cv::Scalar(0));
  if (baseline <= 0.0) return shadowed;
  for (int v = 0; v < depth.rows; ++v) {
    double leftmost = std::numeric_limits<double>::infinity();
    for (int u = depth.cols - 1; u >= 0; --u) {
      const double z = depth.at<float>(v, u);
      if (z <= 0.0) continue;
      const double landing = u - fx * baseline / z;
      if (landing > leftmost) shadowed.at<uchar>(v, u) = 255;
      else leftmost = landing;
    }
  }
  return shadowed;
}

/// Turns a clean render into a sensor reading: depth in metres (0 = no reading), BGR 8-bit.
/// Deterministic for a given seed.
inline void applySensorModel(const RenderBuffers& clean, const PinholeCamerad& camera, const SensorSettings& s,
                             unsigned seed, cv::Mat& depth, cv::Mat& color) {
  std::mt19937 rng(seed), mixing_rng(seed ^ 0x5bd1e995u);  // flying pixels draw apart: other streams unchanged
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double cos_grazing = std::cos(radians(s.grazing_angle_deg));
  depth = cv::Mat(clean.depth.size(), CV_32FC1, cv::Scalar(0));
  const double shadow_baseline = s.shadow && triangulates(s.depth_noise) ? s.depth_noise.baseline : 0.0;
  const cv::Mat shadowed = shadowedPixels(clean.depth, camera.fx, shadow_baseline);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const double noise = gauss(rng), dropout = uniform(rng);  // drawn for every pixel: stable streams
      const double z = clean.depth.at<float>(v, u);
      if (z <= s.min_range || z >= s.max_range || dropout < s.random_dropout || shadowed.at<uchar>(v, u)) continue;
      bool edge = false;
      double across = z;  // the 4-neighbour's depth farthest from z
      for (const auto& [dv, du] : {std::pair{0, 1}, {0, -1}, {1, 0}, {-1, 0}}) {
        const int vv = v + dv, uu = u + du;
        if (vv < 0 || uu < 0 || vv >= depth.rows || uu >= depth.cols) continue;
        const double zn = clean.depth.at<float>(vv, uu);
        edge |= zn <= 0.0 || std::abs(zn - z) > s.edge_jump;
        if (zn > 0.0 && std::abs(zn - z) > std::abs(across - z)) across = zn;
      }
      if (edge && dropout < s.edge_dropout) continue;
      const cv::Vec3f& n = clean.normal.at<cv::Vec3f>(v, u);
      const Eigen::Vector3d ray = camera.unproject(u, v, 1.0).normalized();
      if (std::abs(ray.dot(Eigen::Vector3d(n[0], n[1], n[2]))) < cos_grazing) continue;
      double read = z;
      if (edge && s.flying_pixels > 0.0 && uniform(mixing_rng) < s.flying_pixels) read += uniform(mixing_rng) * (across - z);
      depth.at<float>(v, u) = float(s.depth_noise.quantised(read + s.depth_noise.sigma(read, camera.fx) * noise, camera.fx));
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
