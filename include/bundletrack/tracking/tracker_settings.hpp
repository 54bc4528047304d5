#pragma once

#include <cstddef>

#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"

namespace bundletrack {

/// What the pipeline of Tracker decides with (docs/DESIGN.md section 3; the original code's
/// values unless noted). The policies carry their own settings.
struct TrackerSettings {
  /// Fewest RANSAC inliers with the last good frame that count as a coarse pose: the 3 sampled
  /// matches and 2 more that agree within 5 mm and 45 degrees. Small, weakly textured objects give
  /// only 5-10 correct matches per frame (the shared mug: median 7), so a higher bar loses them; a
  /// wrong pose that passes it is caught by the pose graph and its verification.
  int min_inliers = 5;
  std::size_t max_keyframes = 15;  ///< K: keyframes in the pose graph besides the current frame (paper IV-C)
  std::size_t pool_capacity = 200;  ///< keyframes kept in memory (the original pool was unbounded)
  double new_keyframe_rotation_deg = 10.0;  ///< paper IV-E
  int dense_grid_step = 4;  ///< the surface grids (dense term, verification, masks) sample every 4th pixel
  SurfaceGate edge_gate;  ///< feature matches of a graph edge must agree with the current poses
  int min_edge_correspondences = 6;  ///< an edge with fewer feature correspondences has no feature term
  /// RANSAC inliers needed to restart after lost frames (with the last good frame or a keyframe).
  /// Without a motion prior a handful of inliers can be chance: on the synthetic box, 5 of 12
  /// matches gave a pose 172 degrees off; 12 is well above what random matches gather.
  int recovery_min_inliers = 12;
  /// A frame with fewer keypoints than this cannot be re-acquired by features (textureless
  /// objects); after lost frames it is re-acquired by the surface alone: the graph runs from the
  /// last good pose and its verifier sees Evidence::SurfaceOnly. Twice the inliers a feature
  /// recovery needs.
  int recovery_min_keypoints = 24;
  GaussNewtonSettings gauss_newton;
};

}  // namespace bundletrack
