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

/// Starts for a re-acquisition by the surface alone, where the object came back turned: `pose`
/// turned about `pivot` (a camera-frame point on the object) by k * step for k = 1..rings, both
/// ways about each camera axis (6 * rings poses, the nearest ring first). The dense term's basin
/// is a few tens of degrees wide (a chair 2.5 m away: starts 27 to 52 degrees off converge to
/// within 1 degree), so starts a step apart cover the turns up to rings * step.
inline std::vector<SE3d> turnedAbout(const SE3d& pose, const Eigen::Vector3d& pivot, double step_rad, int rings) {
  std::vector<SE3d> starts;
  for (int ring = 1; ring <= rings; ++ring)
    for (int axis = 0; axis < 3; ++axis)
      for (const double sign : {1.0, -1.0}) {
        const SO3d turn = SO3d::exp(sign * ring * step_rad * Eigen::Vector3d::Unit(axis));
        starts.push_back(SE3d(turn, pivot - turn * pivot) * pose);
      }
  return starts;
}

/// Of the poses the pose graph reached from different starts, the largest group within
/// max_angle_rad and max_distance of one of its members, that member first (ties: the earlier
/// member). Right poses are reached from starts far apart; a wrong local minimum rarely is.
inline std::vector<std::size_t> largestConsensus(const std::vector<SE3d>& poses, double max_angle_rad, double max_distance) {
  std::vector<std::size_t> best;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    std::vector<std::size_t> group{i};
    for (std::size_t j = 0; j < poses.size(); ++j)
      if (j != i && rotationGeodesic(poses[i].rotation(), poses[j].rotation()) <= max_angle_rad &&
          (poses[i].translation() - poses[j].translation()).norm() <= max_distance)
        group.push_back(j);
    if (group.size() > best.size()) best = std::move(group);
  }
  return best;
}

}  // namespace bundletrack
