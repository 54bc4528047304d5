#pragma once

#include <concepts>
#include <optional>
#include <vector>

#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/features/frame_features.hpp"
#include "bundletrack/features/matching.hpp"

namespace bundletrack {

/// A source of 3-D feature correspondences (paper IV-B): detects features of a frame inside its
/// object mask, lifted to 3-D, and matches the features of two frames, optionally gated by a known
/// relative pose. Plug in learned features by providing these two members.
template <typename T>
concept CorrespondenceSource = requires(T& source, const T& const_source, const RgbdFrame& frame,
                                        const FrameFeatures& features, const std::optional<MatchGate>& gate) {
  { source.detect(frame) } -> std::same_as<FrameFeatures>;
  { const_source.match(features, features, gate) } -> std::same_as<std::vector<FeatureMatch>>;
};

/// A correspondence source that can also follow the last frame's keypoints (on its grey image and
/// object mask) into the next frame (given with its grey image, which the tracker keeps for the
/// frame after), cheaper than detecting and matching them (Tracker: keypoints on demand).
template <typename T>
concept FollowingSource = CorrespondenceSource<T> && requires(const T& source, const cv::Mat& last_gray,
                                                               const cv::Mat& last_mask, const FrameFeatures& last,
                                                               const RgbdFrame& frame, const cv::Mat& gray) {
  { source.follow(last_gray, last_mask, last, frame, gray) } -> std::same_as<FollowedFeatures>;
};

}  // namespace bundletrack
