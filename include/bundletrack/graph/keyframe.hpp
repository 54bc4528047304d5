#pragma once

#include <string>

#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/core/surface_grid.hpp"
#include "bundletrack/features/frame_features.hpp"

namespace bundletrack {

/// What the pose graph keeps of a frame: its pose, its features (paper eq. 2) and its surface on
/// the dense grid (paper eq. 3).
struct Keyframe {
  int id = 0;  ///< frame index in the sequence
  std::string name;
  SE3d T_cam_obj;
  FrameFeatures features;
  SurfaceGrid surface;
};

/// The keyframe of `frame` under `mask`, its surface sampled every `grid_step` pixels.
inline Keyframe makeKeyframe(int id, const RgbdFrame& frame, const cv::Mat& mask, FrameFeatures features,
                             const SE3d& T_cam_obj, const PinholeCameraf& camera, int grid_step) {
  return {id, frame.name, T_cam_obj, std::move(features), sampleSurface(frame, mask, camera, grid_step)};
}

}  // namespace bundletrack
