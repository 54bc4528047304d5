#pragma once

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <opencv2/features2d.hpp>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/features/frame_features.hpp"

namespace bundletrack {

struct MatchSettings {
  float ratio = 0.8f;  ///< Lowe's ratio test: best distance < ratio * second best, in both directions
};

/// Geometric gate for a pair whose relative pose is already known (DESIGN.md section 3: 2 cm and
/// 45 degrees for non-consecutive pairs): a match survives when the first point, moved by
/// T_second_first, lies within max_distance of the second and their normals within the angle.
struct MatchGate {
  SE3f T_second_first;
  float max_distance = 0.02f;  ///< metres
  float max_normal_angle_deg = 45.0f;
};

/// Mutual nearest neighbours in descriptor space with the ratio test applied in both directions,
/// so match(a, b) is match(b, a) with the roles swapped (the original code took the union of the
/// two directions instead). Sorted by the first index.
inline std::vector<FeatureMatch> matchFeatures(const FrameFeatures& first, const FrameFeatures& second,
                                               const MatchSettings& settings,
                                               const std::optional<MatchGate>& gate = std::nullopt) {
  std::vector<FeatureMatch> matches;
  if (first.size() < 2 || second.size() < 2) return matches;  // no second neighbour for the ratio test
  const cv::BFMatcher matcher(first.norm_type);
  std::vector<std::vector<cv::DMatch>> forward, backward;
  matcher.knnMatch(first.descriptors, second.descriptors, forward, 2);
  matcher.knnMatch(second.descriptors, first.descriptors, backward, 2);
  const auto distinct = [&](const std::vector<cv::DMatch>& knn) {
    return knn.size() == 2 && knn[0].distance < settings.ratio * knn[1].distance;
  };
  const float cos_max = gate ? std::cos(gate->max_normal_angle_deg * std::numbers::pi_v<float> / 180.0f) : -1.0f;
  for (int i = 0; i < int(forward.size()); ++i) {
    if (!distinct(forward[i])) continue;
    const int j = forward[i][0].trainIdx;
    if (!distinct(backward[j]) || backward[j][0].trainIdx != i) continue;
    if (gate) {
      const Eigen::Vector3f moved = gate->T_second_first * first.points[i];
      const Eigen::Vector3f turned = gate->T_second_first.rotation() * first.normals[i];
      if ((moved - second.points[j]).norm() > gate->max_distance || turned.dot(second.normals[j]) < cos_max) continue;
    }
    matches.push_back({i, j});
  }
  return matches;
}

}  // namespace bundletrack
