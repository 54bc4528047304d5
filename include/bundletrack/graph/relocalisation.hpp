#pragma once

#include <algorithm>
#include <numeric>
#include <optional>
#include <vector>

#include "bundletrack/graph/keyframe_pool.hpp"

namespace bundletrack {

/// Re-acquisition after lost frames from the keyframes: the pool's keyframes nearest in rotation to
/// the last good pose first (at most max_keyframes), each registered with the frame by
/// register_with(keyframe) (a result with T_second_first, keyframe to frame, and inliers); the pose
/// from the keyframe with the most inliers, when it has at least min_inliers.
template <typename RegisterWith>
std::optional<SE3d> relocalise(const KeyframePool& pool, const SO3d& last_rotation, std::size_t max_keyframes,
                               int min_inliers, RegisterWith&& register_with) {
  std::vector<std::size_t> order(pool.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return rotationGeodesic(pool[a].T_cam_obj.rotation(), last_rotation) <
           rotationGeodesic(pool[b].T_cam_obj.rotation(), last_rotation);
  });
  order.resize(std::min(order.size(), max_keyframes));
  std::optional<SE3d> best;
  int best_inliers = min_inliers - 1;
  for (const std::size_t k : order) {
    const auto registration = register_with(pool[k]);
    if (int(registration.inliers.size()) > best_inliers) {
      best_inliers = int(registration.inliers.size());
      best = registration.T_second_first * pool[k].T_cam_obj;
    }
  }
  return best;
}

}  // namespace bundletrack
