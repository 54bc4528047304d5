#pragma once

#include <concepts>
#include <optional>
#include <span>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// A part of the tracked object as one frame saw it: that frame's object points (camera frame, on
/// the dense grid of the pose graph, zero where there is none) and its object pose.
struct ObservedSurface {
  cv::Mat points;  ///< CV_32FC3
  SE3d T_cam_obj;
};

/// Masks that exist independently of the track (from the data, or a segmentation network):
/// `mask(frame)` returns CV_8UC1, 255 on the object; all zero when the object is not visible.
template <typename T>
concept FrameMaskSource = requires(T& source, const RgbdFrame& frame) {
  { source.mask(frame) } -> std::same_as<cv::Mat>;
};

/// Masks that follow the object from the first one (the tracker supplies what it knows):
/// - `start(first, camera, T_cam_obj, grid_step)`: the first frame with its mask and pose;
/// - `searchRegion(frame, object, T_guess)`: where to look for keypoints before the coarse pose
///   is known (std::nullopt: no idea where the object is, e.g. after it was lost);
/// - `mask(frame, object, T_cam_obj)`: the object mask under the coarse pose.
template <typename T>
concept PropagatedMaskSource =
    requires(T& source, const RgbdFrame& frame, const PinholeCameraf& camera, const SE3d& pose,
             std::span<const ObservedSurface> object, const std::optional<SE3d>& guess, int step) {
      source.start(frame, camera, pose, step);
      { source.searchRegion(frame, object, guess) } -> std::same_as<cv::Mat>;
      { source.mask(frame, object, pose) } -> std::same_as<cv::Mat>;
    };

template <typename T>
concept MaskSource = FrameMaskSource<T> || PropagatedMaskSource<T>;

}  // namespace bundletrack
