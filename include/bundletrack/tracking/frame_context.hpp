#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/graph/pose_graph.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"
#include "bundletrack/tracking/track_result.hpp"
#include "bundletrack/verification/pose_verifier.hpp"

namespace bundletrack {

/// A coarse pose of a frame (paper IV-B) and what stands behind it.
struct CoarseEstimate {
  SE3d T_cam_obj;  ///< the last good pose when nothing better was found
  bool found = false;  ///< from RANSAC, with the last good frame or a keyframe
  bool from_last = false;  ///< from RANSAC with the last good frame, whose inliers are below
  Evidence evidence = Evidence::Features;  ///< SurfaceOnly: the verifier's stricter test decides
  std::vector<FeatureMatch> last_inliers;  ///< the matches with the last good frame that RANSAC kept
};

/// Following's result where RANSAC kept min_inliers but the frame was not taken on it (short of
/// follow_min_share, or its graph refused): kept for Tracker::refineFromFollowing.
struct FollowedReserve {
  FrameFeatures keypoints;  ///< the last good frame's keypoints, followed into this frame
  CoarseEstimate coarse;  ///< the pose RANSAC gives on them, its inliers indexing `keypoints`
};

/// Everything the pipeline's stages know about one frame, in the order they learn it.
struct FrameContext {
  FrameContext(const RgbdFrame& frame_, int id_, bool recovering_)
      : frame(frame_), id(id_), recovering(recovering_), masked(frame_) {}

  const RgbdFrame& frame;
  int id;
  bool recovering;  ///< the frames before were lost, or this one is re-acquired at once (next)
  bool reacquiring_at_once = false;  ///< every candidate from the last good frame was refused (Tracker::reacquireAtOnce)
  RgbdFrame masked;  ///< the frame with the mask the stages work on (shares the image buffers)
  FrameFeatures features;  ///< detected; moves into `current` when the graph is built
  bool keypoints_detected = false;  ///< on this frame (not always with keypoints on demand)
  bool keypoints_followed = false;  ///< the last good frame's keypoints, followed into this frame (optical flow)
  int chain_start = 0;  ///< then: how many keypoints the chain of followed frames began with
  std::optional<FollowedReserve> followed_reserve;
  std::optional<FrameFeatures> detected_kept;  ///< then: the detected keypoints, where they found no pose with the last frame
  cv::Mat gray;  ///< the frame's grey image, once made (following keypoints reads it, and the next frame follows on it)
  std::vector<CoarseEstimate> candidates;  ///< coarse poses to try, in order (several only after lost frames)
  CoarseEstimate coarse;  ///< the one being tried
  std::vector<FeatureMatch> coarse_evidence;  ///< its inliers with the last good frame (the graph may take coarse's)
  Keyframe current;  ///< the frame as a graph node
  cv::Mat current_mask;  ///< the mask `current`'s grid and images were made under (its buffer kept: no other mask shares it)
  PoseGraph graph;
  OptimizationReport optimisation;
  TrackResult result;
};

}  // namespace bundletrack
