#pragma once

#include <optional>
#include <vector>

#include "bundletrack/graph/pose_graph.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bundletrack {

/// The coarse pose of a frame (paper IV-B) and where it came from.
struct CoarseEstimate {
  SE3d T_cam_obj;  ///< the last good pose when nothing better was found
  bool found = false;  ///< from RANSAC, with the last good frame or a keyframe
  bool from_last = false;  ///< from RANSAC with the last good frame, whose inliers are below
  bool by_surface = false;  ///< a texture-poor frame after lost frames: the surface alone must re-acquire it
  std::vector<FeatureMatch> last_inliers;  ///< the matches with the last good frame that RANSAC kept
};

/// Everything the pipeline's stages know about one frame, in the order they learn it.
struct FrameContext {
  FrameContext(const RgbdFrame& frame_, int id_, bool recovering_)
      : frame(frame_), id(id_), recovering(recovering_), masked(frame_) {}

  const RgbdFrame& frame;
  int id;
  bool recovering;  ///< the frames before were lost
  RgbdFrame masked;  ///< the frame with the mask the stages work on (shares the image buffers)
  FrameFeatures features;  ///< detected; moves into `current` when the graph is built
  CoarseEstimate coarse;
  Keyframe current;  ///< the frame as a graph node
  PoseGraph graph;
  OptimizationReport optimisation;
  TrackResult result;
};

}  // namespace bundletrack
