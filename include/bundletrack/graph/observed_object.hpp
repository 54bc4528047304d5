#pragma once

#include <vector>

#include "bundletrack/graph/keyframe_pool.hpp"

namespace bundletrack {

/// A part of the tracked object as one frame saw it: that frame's object points (camera frame, on
/// the dense grid, zero where there is none) and its object pose.
struct ObservedSurface {
  cv::Mat points;  ///< CV_32FC3
  SE3d T_cam_obj;
};

/// What the tracker has seen of the object, for mask sources that follow it: asked for a pose, the
/// last good frame's surface and those of the keyframes the pose graph would select there.
/// Computed only when asked (given masks never ask).
class ObservedObject {
 public:
  ObservedObject(ObservedSurface last, const KeyframePool& pool, std::size_t max_keyframes)
      : last_(std::move(last)), pool_(pool), max_keyframes_(max_keyframes) {}

  std::vector<ObservedSurface> surfaces(const SE3d& T_cam_obj) const {
    std::vector<ObservedSurface> seen{last_};
    for (const std::size_t k : pool_.select(T_cam_obj.rotation(), max_keyframes_))
      seen.push_back({pool_[k].surface.points, pool_[k].T_cam_obj});
    return seen;
  }

 private:
  ObservedSurface last_;
  const KeyframePool& pool_;
  std::size_t max_keyframes_;
};

}  // namespace bundletrack
