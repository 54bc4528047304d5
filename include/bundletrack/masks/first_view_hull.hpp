#pragma once

#include <cmath>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// Where the object can be, from its first view alone: every object point projects into the first
/// mask (dilated for pose and calibration error) and lies behind the surface the first frame saw
/// there, by no more than the object's visible extent (its bounding-box diagonal in that frame):
/// a one-view visual hull, cut at the depth an object as deep as it is wide would reach.
/// A part hidden by an occluder in the first frame lies outside the hull. The depth tolerance in
/// front of that surface is widened by the first frame's NoiseScale at the depth seen.
class FirstViewHull {
 public:
  FirstViewHull() = default;

  FirstViewHull(const RgbdFrame& first, const PinholeCameraf& camera, const SE3d& T_cam_obj, int dilation_px,
                float depth_tolerance)
      : camera_(camera), T_cam_obj_(T_cam_obj), depth_(first.depth), noise_(first.noise),
        depth_tolerance_(depth_tolerance) {
    cv::dilate(first.mask, mask_, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * dilation_px + 1, 2 * dilation_px + 1}));
    Eigen::Array3f low = Eigen::Array3f::Constant(INFINITY), high = -low;
    for (int v = 0; v < first.mask.rows; ++v) {
      for (int u = 0; u < first.mask.cols; ++u) {
        const cv::Vec3f& p = first.points.at<cv::Vec3f>(v, u);
        if (!first.mask.at<uchar>(v, u) || p[2] <= 0.0f) continue;
        low = low.min(Eigen::Array3f(p[0], p[1], p[2]));
        high = high.max(Eigen::Array3f(p[0], p[1], p[2]));
      }
    }
    extent_ = (high >= low).all() ? (high - low).matrix().norm() : 0.0f;
  }

  float extent() const { return extent_; }

  bool contains(const Eigen::Vector3d& p_obj) const {
    const Eigen::Vector3f p = (T_cam_obj_ * p_obj).cast<float>();
    int u = 0, v = 0;
    if (!camera_.pixelOf(p, u, v)) return false;
    if (u < 0 || v < 0 || u >= mask_.cols || v >= mask_.rows || !mask_.at<uchar>(v, u)) return false;
    const float seen = depth_.at<float>(v, u);
    return seen <= 0.0f || (p.z() >= seen - noise_.widen(depth_tolerance_, seen) && p.z() <= seen + extent_);
  }

 private:
  PinholeCameraf camera_{};
  SE3d T_cam_obj_;
  cv::Mat mask_, depth_;
  NoiseScale noise_;
  float depth_tolerance_ = 0.0f;
  float extent_ = 0.0f;
};

}  // namespace bundletrack
