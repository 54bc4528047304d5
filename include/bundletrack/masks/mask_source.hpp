#pragma once

#include <concepts>
#include <optional>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/graph/observed_object.hpp"

namespace bundletrack {

/// Where the object is in each frame (the paper's segmentation step). Masks are CV_8UC1, 255 on
/// the object, all zero where it is not visible. The tracker asks several times per frame, giving
/// what it knows; a source whose masks exist independently of the track (GivenMasks: from the
/// data or a segmentation network) ignores the poses, one that follows the object (PropagatedMasks)
/// renders what was seen (`object`) under them. Before the frame is preprocessed:
/// - `regionOfInterest(image, given_mask, object, T_guess)`: the part of the image whose depth the
///   calls below will read (given_mask: the frame's mask from the data, empty if none);
/// then, with the preprocessed frame:
/// - `frameMask(frame)`: first and once: the frame's own mask as the source reads it (GivenMasks:
///   the data's, less the background it took in beside the object; PropagatedMasks: as given, read
///   at the start only); the calls below get the frame with this mask;
/// - `start(first, camera, T_cam_obj, grid_step)`: the first frame and its pose; returns its mask;
/// - `searchRegion(frame, object, T_guess)`: where to look for keypoints before the coarse pose is
///   known (std::nullopt: no idea where the object is, e.g. after it was lost);
/// - `mask(frame, object, T_cam_obj)`: the object's mask under a pose (the coarse one, then the
///   final one; returning the same cv::Mat again means the mask does not depend on the pose).
template <typename T>
concept MaskSource = requires(T& source, const T& const_source, const RgbdFrame& frame, const PinholeCameraf& camera,
                              const SE3d& pose, const ObservedObject& object, const std::optional<SE3d>& guess, int step,
                              cv::Size image, const cv::Mat& given_mask) {
  { const_source.regionOfInterest(image, given_mask, object, guess) } -> std::same_as<cv::Rect>;
  { const_source.frameMask(frame) } -> std::same_as<cv::Mat>;
  { source.start(frame, camera, pose, step) } -> std::same_as<cv::Mat>;
  { const_source.searchRegion(frame, object, guess) } -> std::same_as<cv::Mat>;
  { const_source.mask(frame, object, pose) } -> std::same_as<cv::Mat>;
};

}  // namespace bundletrack
