#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/features/frame_features.hpp"

namespace bundletrack {

/// What the pose graph keeps of a frame: its features, and its object points and normals on a
/// grid downsampled by `step` (pixel (x, y) of the grid is full-resolution pixel (step x, step y)),
/// zero outside the mask or without depth, for the dense term (paper eq. 3).
struct Keyframe {
  int id = 0;  ///< frame index in the sequence
  std::string name;
  SE3d T_cam_obj;
  FrameFeatures features;
  cv::Mat points;  ///< CV_32FC3, downsampled
  cv::Mat normals;  ///< CV_32FC3, downsampled
  std::vector<cv::Point> surface;  ///< the grid cells that hold a point (see indexSurface)
};

/// Lists the grid cells with a point, so that the dense term visits only those.
inline void indexSurface(Keyframe& keyframe) {
  keyframe.surface.clear();
  for (int y = 0; y < keyframe.points.rows; ++y)
    for (int x = 0; x < keyframe.points.cols; ++x)
      if (keyframe.points.at<cv::Vec3f>(y, x)[2] > 0.0f) keyframe.surface.emplace_back(x, y);
}

/// The camera of the downsampled grid: u_full = step * x, so fx' = fx / step and cx' = cx / step.
inline PinholeCameraf downsampledCamera(const PinholeCameraf& camera, int step) {
  const float s = 1.0f / float(step);
  return {camera.fx * s, camera.fy * s, camera.cx * s, camera.cy * s};
}

inline Keyframe makeKeyframe(int id, const RgbdFrame& frame, const cv::Mat& mask, FrameFeatures features,
                             const SE3d& T_cam_obj, int step) {
  Keyframe keyframe{id, frame.name, T_cam_obj, std::move(features), {}, {}, {}};
  const cv::Size size((frame.points.cols + step - 1) / step, (frame.points.rows + step - 1) / step);
  keyframe.points.create(size, CV_32FC3);
  keyframe.normals.create(size, CV_32FC3);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const int u = step * x, v = step * y;
      const cv::Vec3f& n = frame.normals.at<cv::Vec3f>(v, u);
      const bool use = mask.at<uchar>(v, u) && frame.points.at<cv::Vec3f>(v, u)[2] > 0.0f && n[2] != 0.0f;
      keyframe.points.at<cv::Vec3f>(y, x) = use ? frame.points.at<cv::Vec3f>(v, u) : cv::Vec3f(0, 0, 0);
      keyframe.normals.at<cv::Vec3f>(y, x) = use ? n : cv::Vec3f(0, 0, 0);
    }
  }
  indexSurface(keyframe);
  return keyframe;
}

}  // namespace bundletrack
