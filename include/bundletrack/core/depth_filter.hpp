#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/depth_noise.hpp"

namespace bundletrack {

/// How a smoothing pass combines the neighbours it admits (docs/DESIGN.md section 7).
enum class DepthSmoothing {
  Mean,  ///< their Gaussian-weighted mean (the original code's filter)
  PlaneFit,  ///< the value at the pixel of their Gaussian-weighted least-squares plane
};

/// Depth clean-up before anything uses the depth (docs/DESIGN.md section 3, after the original code).
struct DepthFilterSettings {
  float min_depth = 0.1f;  ///< metres; closer readings are invalid (below any RGB-D sensor's range)
  float max_depth = std::numeric_limits<float>::infinity();  ///< metres; farther readings are invalid
  int erode_radius = 1;  ///< pixels; 1 = 3x3 neighbourhood
  /// metres; a neighbour farther than this in depth counts against the pixel, and farther than 3
  /// standard deviations of the difference of two readings (3 sqrt(2) NoiseScale::spread(z)):
  /// the test is for flying pixels and isolated readings, and noise alone must not erode. The
  /// original code's 1 mm on whole millimetres (kept as 1.5 mm on float depth) flagged every
  /// change of disparity level; at 2.5 m, where structured light's levels are 17 mm apart and
  /// the noise flips readings between them, it eroded a fifth of a smooth surface.
  float erode_depth_diff = 0.0015f;
  float erode_ratio = 0.8f;  ///< a pixel is removed when this fraction of its neighbours count against it
  int smooth_radius = 2;  ///< pixels; 2 = 5x5 window
  float smooth_sigma = 2.0f;  ///< pixels; spatial Gaussian of the smoothing
  float smooth_depth_window = 0.01f;  ///< metres; only neighbours this close to the pixel's depth are averaged
  int smooth_passes = 2;
  /// PlaneFit: on the stress matrix (bench/ACCURACY.md) the mug's rotation error where its handle
  /// is visible falls from 6.0 to 3.3 degrees at 1 m, a mug 3 m away goes from 86.6 to 96.2 ADD-S,
  /// the shared sequences stay within 0.05 ADD-S; the mean is the original code's.
  DepthSmoothing smoothing = DepthSmoothing::PlaneFit;
};

/// Zero invalid (non-finite, out of range) readings so that 0 is the one invalid value downstream.
inline void invalidateOutOfRange(cv::Mat& depth, const DepthFilterSettings& s) {
  depth.forEach<float>([&](float& z, const int*) {
    if (!std::isfinite(z) || z < s.min_depth || z > s.max_depth) z = 0.0f;
  });
}

/// Removes isolated readings and the flying pixels of depth edges: a valid pixel goes when at least
/// erode_ratio of its neighbours are invalid or differ from it by more than erode_depth_diff or
/// three standard deviations of the difference of two readings at its depth.
inline cv::Mat erodeDepth(const cv::Mat& depth, const DepthFilterSettings& s, const NoiseScale& noise = NoiseScale()) {
  CV_Assert(depth.type() == CV_32FC1);
  cv::Mat out = depth.clone();
  const int r = s.erode_radius;
  const int neighbours = (2 * r + 1) * (2 * r + 1) - 1;
  out.forEach<float>([&](float& z_out, const int* pos) {
    const int v = pos[0], u = pos[1];
    const float z = depth.at<float>(v, u);
    if (z <= 0.0f || neighbours == 0) return;
    const float diff = std::max(s.erode_depth_diff, float(3.0 * std::sqrt(2.0) * noise.spread(z)));
    int against = 0;
    for (int dv = -r; dv <= r; ++dv) {
      for (int du = -r; du <= r; ++du) {
        if (du == 0 && dv == 0) continue;
        const int vv = v + dv, uu = u + du;
        const bool inside = vv >= 0 && vv < depth.rows && uu >= 0 && uu < depth.cols;
        const float zn = inside ? depth.at<float>(vv, uu) : 0.0f;
        if (zn <= 0.0f || std::abs(zn - z) > diff) ++against;
      }
    }
    if (against >= s.erode_ratio * neighbours) z_out = 0.0f;
  });
  return out;
}

/// One pass of edge-preserving smoothing: each valid pixel is replaced from the valid neighbours
/// whose depth lies within smooth_depth_window (widened by `noise` at its depth) of its own, with
/// Gaussian spatial weights: by their mean (DepthSmoothing::Mean) or by the value at the pixel of
/// their weighted least-squares plane z = a + b du + c dv (PlaneFit). The mean flattens slanted
/// and curved surfaces wherever the window admits more neighbours on one side (the rim of a
/// rounded body, a mug's handle), a distortion fixed to the camera that holds a turning object
/// back; the plane is exact on any slanted plane.
/// The original code compared with the window's mean depth instead; at a silhouette whose window
/// is mostly background that mean is background, and the object pixel took the background's depth
/// (measured on the synthetic sequences: a third of the mask's border pixels moved by > 10 cm).
inline cv::Mat smoothDepth(const cv::Mat& depth, const DepthFilterSettings& s, const NoiseScale& noise = NoiseScale()) {
  CV_Assert(depth.type() == CV_32FC1);
  cv::Mat out = depth.clone();
  const int r = s.smooth_radius, width = 2 * r + 1;
  std::vector<float> spatial(std::size_t(width * width));
  for (int dv = -r; dv <= r; ++dv)
    for (int du = -r; du <= r; ++du)
      spatial[std::size_t((dv + r) * width + du + r)] =
          std::exp(-float(du * du + dv * dv) / (2.0f * s.smooth_sigma * s.smooth_sigma));
  const bool plane = s.smoothing == DepthSmoothing::PlaneFit;
  // The first moments are gathered a row at a time, neighbour offset by neighbour offset, so that
  // one pixel's sums run in the same order as a pixel-by-pixel loop (the same floats) while the
  // compiler vectorises across the row. Outside the image the border reads 0, which the window
  // test refuses as it refuses an invalid reading.
  cv::Mat padded;
  cv::copyMakeBorder(depth, padded, r, r, r, r, cv::BORDER_CONSTANT, cv::Scalar(0.0f));
  cv::parallel_for_(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
    const auto cols = std::size_t(depth.cols);
    std::vector<float> windows(cols), w0s(cols), wzs(cols);
    std::vector<int> admitted_counts(cols);
    for (int v = rows.start; v < rows.end; ++v) {
      const float* centre = padded.ptr<float>(v + r) + r;
      for (std::size_t u = 0; u < cols; ++u) windows[u] = noise.widen(s.smooth_depth_window, centre[u]);
      std::fill(w0s.begin(), w0s.end(), 0.0f);
      std::fill(wzs.begin(), wzs.end(), 0.0f);
      std::fill(admitted_counts.begin(), admitted_counts.end(), 0);
      for (int dv = -r; dv <= r; ++dv) {
        for (int du = -r; du <= r; ++du) {
          const float* row = padded.ptr<float>(v + r + dv) + r + du;
          const float w = spatial[std::size_t((dv + r) * width + du + r)];
          for (std::size_t u = 0; u < cols; ++u) {
            const float dz = row[u] - centre[u];
            const bool in = std::abs(dz) < windows[u];
            const float weight = in ? w : 0.0f;  // a select, which the compiler vectorises
            admitted_counts[u] += in ? 1 : 0;
            w0s[u] += weight, wzs[u] += weight * dz;
          }
        }
      }
      const int v0 = std::max(0, v - r), v1 = std::min(depth.rows - 1, v + r);
      for (int u = 0; u < depth.cols; ++u) {
        const float z = centre[u];
        if (z <= 0.0f) continue;
        const int u0 = std::max(0, u - r), u1 = std::min(depth.cols - 1, u + r);
        const float window = windows[std::size_t(u)];
        const float w0 = w0s[std::size_t(u)], wz = wzs[std::size_t(u)];
        const int admitted = admitted_counts[std::size_t(u)];
        float offset = wz / w0;  // the centre itself is always admitted
        // With every neighbour of the whole window admitted the design is symmetric (the first
        // moments vanish), and the plane's value at the pixel is the mean: the plane's other
        // moments are needed only where neighbours are missing or refused.
        if (plane && admitted < width * width) {
          float wu = 0, wv = 0, wuu = 0, wuv = 0, wvv = 0, wuz = 0, wvz = 0;
          for (int vv = v0; vv <= v1; ++vv) {
            const float* row = depth.ptr<float>(vv);
            const float* w = &spatial[std::size_t((vv - v + r) * width - u + r)];
            const float dv = float(vv - v);
            for (int uu = u0; uu <= u1; ++uu) {
              const float dz = row[uu] - z, du = float(uu - u);
              const float weight = float(std::abs(dz) < window) * w[uu];
              wu += weight * du, wv += weight * dv, wuu += weight * du * du, wuv += weight * du * dv;
              wvv += weight * dv * dv, wuz += weight * du * dz, wvz += weight * dv * dz;
            }
          }
          // The normal equations' solution for a (Cramer's rule); where they are singular (the
          // admitted neighbours on one line) the mean stays.
          const double det = double(w0) * (double(wuu) * wvv - double(wuv) * wuv) -
                             double(wu) * (double(wu) * wvv - double(wuv) * wv) +
                             double(wv) * (double(wu) * wuv - double(wuu) * wv);
          const double a = (double(wz) * (double(wuu) * wvv - double(wuv) * wuv) -
                            double(wu) * (double(wuz) * wvv - double(wuv) * wvz) +
                            double(wv) * (double(wuz) * wuv - double(wuu) * wvz)) / det;
          if (std::abs(det) > 1e-6 * double(w0) * w0 * w0 && std::abs(a) < window) offset = float(a);
        }
        out.ptr<float>(v)[u] = z + offset;
      }
    }
  });
  return out;
}

/// The whole clean-up: range check, erosion, then smooth_passes smoothing passes.
inline cv::Mat filterDepth(const cv::Mat& raw_depth, const DepthFilterSettings& s, const NoiseScale& noise = NoiseScale()) {
  cv::Mat depth = raw_depth.clone();
  invalidateOutOfRange(depth, s);
  depth = erodeDepth(depth, s, noise);
  for (int pass = 0; pass < s.smooth_passes; ++pass) depth = smoothDepth(depth, s, noise);
  return depth;
}

}  // namespace bundletrack
