#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

#include "bundletrack/graph/keyframe_pool.hpp"

namespace bundletrack {

/// A pose for a frame after lost frames, from a registration with a keyframe.
struct RelocalisedPose {
  SE3d T_cam_obj;
  int inliers = 0;
};

/// Re-acquisition after lost frames from the keyframes: the pool's keyframes nearest in rotation to
/// the last good pose first (at most max_keyframes), each registered with the frame by
/// register_with(keyframe) (a result with T_second_first, keyframe to frame, and inliers); the poses
/// of those with at least min_inliers inliers, most inliers first (ties: nearest in rotation first).
template <typename RegisterWith>
std::vector<RelocalisedPose> relocalise(const KeyframePool& pool, const SO3d& last_rotation, std::size_t max_keyframes,
                                        int min_inliers, RegisterWith&& register_with) {
  std::vector<std::size_t> order(pool.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return rotationGeodesic(pool[a].T_cam_obj.rotation(), last_rotation) <
           rotationGeodesic(pool[b].T_cam_obj.rotation(), last_rotation);
  });
  order.resize(std::min(order.size(), max_keyframes));
  std::vector<RelocalisedPose> poses;
  for (const std::size_t k : order) {
    const auto registration = register_with(pool[k]);
    if (int(registration.inliers.size()) >= min_inliers)
      poses.push_back({registration.T_second_first * pool[k].T_cam_obj, int(registration.inliers.size())});
  }
  std::stable_sort(poses.begin(), poses.end(), [](const RelocalisedPose& a, const RelocalisedPose& b) { return a.inliers > b.inliers; });
  return poses;
}

}  // namespace bundletrack
