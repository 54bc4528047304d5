#pragma once

#include <optional>
#include <string_view>

#include <opencv2/core.hpp>

#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// How a frame's pose was obtained.
enum class TrackStatus {
  Tracked,  ///< refined by the pose graph (or the first frame)
  CoarseOnly,  ///< from RANSAC between consecutive frames only
  Lost,  ///< no trustworthy estimate: the pose is the last good one, flagged, never a silent repeat
};

inline std::string_view statusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::Tracked: return "tracked";
    case TrackStatus::CoarseOnly: return "coarse";
    default: return "lost";
  }
}

/// The status that statusName gives `name`; none for any other text.
inline std::optional<TrackStatus> statusFromName(std::string_view name) {
  for (const TrackStatus status : {TrackStatus::Tracked, TrackStatus::CoarseOnly, TrackStatus::Lost})
    if (statusName(status) == name) return status;
  return std::nullopt;
}

/// Wall-clock milliseconds spent per stage of one frame. `matching` and `ransac` are the coarse
/// step's (and following's RANSAC); the pose graph's edge correspondences, each edge matched and
/// pruned by RANSAC (in parallel over the current frame's edges), are all `matching`.
struct StageTimings {
  double mask = 0.0, features = 0.0, matching = 0.0, ransac = 0.0, graph = 0.0, solve = 0.0, total = 0.0;
};

/// The tracker's answer for one frame.
struct TrackResult {
  SE3d T_cam_obj;
  TrackStatus status = TrackStatus::Lost;
  int keypoints = 0;  ///< features detected on this frame
  int matches = 0;  ///< matches with the previous frame
  int inliers = 0;  ///< RANSAC inliers among them
  cv::Mat mask;  ///< the object mask the frame was tracked with; empty when none was made
  StageTimings timings;
  bool surface_only = false;  ///< tracked by the dense term alone (keypoints on demand)
  int followed = 0;  ///< keypoints followed into this frame from the one before by optical flow (when it used them)
  /// How evenly the data hold the pose (poseStability of the frame's information in the accepted
  /// graph, every term as the energy weighs it): up to 1 when every direction is held alike, ~0
  /// where one is held far less than the strongest (a textureless mug's turn with its handle
  /// hidden); a ratio, not an uncertainty. None without a graph's pose (first frame, coarse, lost).
  std::optional<double> stability = std::nullopt;
};

}  // namespace bundletrack
