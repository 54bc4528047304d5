#pragma once

#include <concepts>
#include <vector>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/features/frame_features.hpp"

namespace bundletrack {

/// What the tracker asks of its robust registration (paper IV-B; Ransac, cuda::Ransac): from two
/// frames' features and their matches, the pose mapping the first frame's points onto the
/// second's (`T_second_first`) and the matches it explains (`inliers`, indices into the matches).
template <typename T>
concept FeatureRegistration =
    requires(const T& registration, const FrameFeatures& features, const std::vector<FeatureMatch>& matches) {
      { registration.estimate(features, features, matches).T_second_first } -> std::convertible_to<SE3d>;
      { registration.estimate(features, features, matches).inliers } -> std::convertible_to<std::vector<int>>;
    };

}  // namespace bundletrack
