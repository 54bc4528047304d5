#pragma once

#include <concepts>

#include "bundletrack/graph/pose_graph.hpp"

namespace bundletrack {

/// What stands behind the pose the tracker asks a verifier about.
enum class Evidence {
  Features,  ///< feature matches with RANSAC inliers gave the coarse pose
  SurfaceOnly,  ///< nothing but the surface: a texture-poor frame re-acquired from the last good pose
  /// nothing but the surface, but the pose graph reached the pose from several starts far apart
  /// (largestConsensus): as trustworthy as a feature registration
  SurfaceConsensus,
};

/// Decides whether the pose graph's result for the current frame (its last node) can be trusted;
/// a frame whose pose it refuses falls back to the coarse pose or is lost.
template <typename T>
concept PoseVerifier = requires(const T& verifier, const PoseGraph& optimised, Evidence evidence) {
  { verifier.accepts(optimised, evidence) } -> std::same_as<bool>;
};

}  // namespace bundletrack
