#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "bundletrack/core/plane_moments.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/features/frame_features.hpp"

namespace bundletrack {

/// Unit normal at pixel (u, v) from a plane fit (smallest eigenvector of the covariance) to the
/// valid points of the (2r+1)^2 window within max_depth_jump (already widened for the sensor's
/// noise) of the centre in depth; faces the
/// camera. Keypoints often sit where the per-pixel normal is undefined (texture edges coincide
/// with depth noise), and the fit is also less noisy. Returns zero when fewer than 6 points fit.
inline Eigen::Vector3f fitNormal(const cv::Mat& points, int u, int v, int r, float max_depth_jump) {
  const cv::Vec3f& c = points.at<cv::Vec3f>(v, u);
  PlaneMoments moments;
  for (int vv = std::max(0, v - r); vv <= std::min(points.rows - 1, v + r); ++vv) {
    for (int uu = std::max(0, u - r); uu <= std::min(points.cols - 1, u + r); ++uu) {
      const cv::Vec3f& p = points.at<cv::Vec3f>(vv, uu);
      if (p[2] <= 0.0f || std::abs(p[2] - c[2]) > max_depth_jump) continue;
      moments.add({p[0], p[1], p[2]});
    }
  }
  if (moments.count < 6) return Eigen::Vector3f::Zero();
  Eigen::Vector3d n = moments.normal();
  if (n.dot(moments.mean()) > 0.0) n = -n;
  return n.cast<float>();
}

/// Lifts full-resolution keypoints to 3-D with the frame's depth; keypoints without a valid depth
/// reading or normal are dropped together with their descriptor row. max_depth_jump is widened by
/// the frame's noise at each keypoint's depth. `lifted`, when given, receives the index in `pixels`
/// of every feature kept.
inline FrameFeatures liftKeypoints(const RgbdFrame& frame, const std::vector<cv::Point2f>& pixels,
                                   const cv::Mat& descriptors, int norm_type, int normal_radius = 3,
                                   float max_depth_jump = 0.02f, std::vector<int>* lifted = nullptr) {
  FrameFeatures features;
  features.norm_type = norm_type;
  std::vector<int> kept;
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const int u = roundToPixel(pixels[k].x), v = roundToPixel(pixels[k].y);
    if (u < 0 || v < 0 || u >= frame.depth.cols || v >= frame.depth.rows) continue;
    const cv::Vec3f& p = frame.points.at<cv::Vec3f>(v, u);
    if (p[2] <= 0.0f) continue;
    const Eigen::Vector3f n = fitNormal(frame.points, u, v, normal_radius, frame.noise.widen(max_depth_jump, p[2]));
    if (n.isZero()) continue;
    features.pixels.push_back(pixels[k]);
    features.points.emplace_back(p[0], p[1], p[2]);
    features.normals.push_back(n);
    kept.push_back(int(k));
  }
  features.descriptors.create(int(kept.size()), descriptors.cols, descriptors.type());
  for (std::size_t i = 0; i < kept.size(); ++i) descriptors.row(kept[i]).copyTo(features.descriptors.row(int(i)));
  std::vector<float> depths;
  for (const Eigen::Vector3f& p : features.points) depths.push_back(p.z());
  features.noise_scale = frame.noise.atMedian(std::move(depths));
  if (lifted) *lifted = std::move(kept);
  return features;
}

}  // namespace bundletrack
