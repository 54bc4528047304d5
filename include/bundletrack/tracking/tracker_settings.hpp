#pragma once

#include <cstddef>

#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/graph/edge_linearisation_cache.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"

namespace bundletrack {

/// When the tracker detects keypoints.
enum class KeypointSchedule {
  EveryFrame,  ///< paper IV: every frame
  /// Only where the dense term alone cannot be trusted (Tracker::trackBySurface): a frame is first
  /// tracked without keypoints, from the last good pose; where the surface seen is geometrically
  /// unstable or the verifier refuses that pose, the last frame's keypoints are followed into it
  /// (Tracker::trackByFollowing, TrackerSettings::follow_keypoints); keypoints are detected when
  /// that fails too, after lost frames and on frames that become keyframes.
  OnDemand,
};

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
  /// The surface grids (dense term, verification, masks) sample the object every step pixels,
  /// chosen from the first mask to give about dense_target_samples points (gridStepFor) and at
  /// most dense_grid_step (the original code's fixed step). Step 4 gives the default synthetic
  /// box (20 cm at 0.73 m, 11900 points on its first mask) 750 points; a target of 600 keeps it
  /// there (step 4 for 9600 to 15000 points), and gives a 10 cm mug at 2 m (~500 points on its
  /// mask) step 1 instead of 30 points.
  int dense_grid_step = 4;
  int dense_target_samples = 600;
  SurfaceGate edge_gate;  ///< feature matches of a graph edge must agree with the current poses
  int min_edge_correspondences = 6;  ///< an edge with fewer feature correspondences has no feature term
  /// RANSAC inliers needed to restart after lost frames (with the last good frame or a keyframe).
  /// Without a motion prior a handful of inliers can be chance: on the synthetic box, 5 of 12
  /// matches gave a pose 172 degrees off; 12 is well above what random matches gather. Below it,
  /// a frame whose graph from RANSAC's pose the verifier refuses also tries the graph from the
  /// last good pose on the surface's evidence before it falls back on RANSAC's pose.
  int recovery_min_inliers = 12;
  /// A graph result must keep this share of the coarse pose's RANSAC inliers with the last good
  /// frame within edge_gate, where there are recovery_min_inliers or more (Tracker's
  /// keepsCoarseEvidence): a half, as followed keypoints must keep (follow_min_share); a graph that
  /// refines the pose by millimetres keeps nearly all, one that diverged keeps none.
  double min_kept_coarse_inliers = 0.5;
  /// A frame that features cannot re-acquire (a textureless object, a far one with 3-5 inliers) is
  /// re-acquired by its surface: the graph runs from each of at most this many coarse poses --
  /// registrations with min_inliers or more inliers (most first), the last good pose, and the last
  /// good pose moved onto the object's points in this frame -- and the first whose result the
  /// verifier accepts on Evidence::SurfaceOnly is kept (0: features alone).
  int recovery_surface_candidates = 4;
  /// The object may come back turned far from where it left: the last good pose moved onto the
  /// object's points is also tried turned about their centroid by k * recovery_turn_step_deg,
  /// k = 1..recovery_turn_rings, both ways about each camera axis (turnedAbout; 0 rings: none).
  double recovery_turn_step_deg = 20.0;
  int recovery_turn_rings = 2;
  /// Every surface candidate of a lost frame is optimised; a pose reached from at least
  /// recovery_min_consensus of them (within recovery_consensus_angle_deg and
  /// recovery_consensus_distance, the distance widened for the sensor's noise) needs only the
  /// verifier's min_agreement (Evidence::SurfaceConsensus); without one the first candidate that
  /// passes recovery_min_agreement is kept. A view turned 27 degrees past every keyframe agrees
  /// with them at only 0.57-0.68 when right (a chair 2.5 m away), while a wrong minimum reached
  /// from one start can pass 0.8 (that chair turned by 90 degrees); right poses were reached from
  /// 8 of 14 starts within 0.6 degrees and 0.5 cm.
  int recovery_min_consensus = 3;
  double recovery_consensus_angle_deg = 2.0;
  float recovery_consensus_distance = 0.01f;
  /// OnDemand by default: on the stress matrix (bench/ACCURACY.md) it is within 0.2 ADD-S of
  /// EveryFrame on every cell, and it skips keypoints on most frames of the shared container and
  /// mug (bench/RESULTS.md); EveryFrame is the paper's schedule.
  KeypointSchedule keypoints = KeypointSchedule::OnDemand;
  /// OnDemand: where the surface alone cannot hold a frame, the last good frame's keypoints, when
  /// it has its own, are first followed into it by optical flow (FollowingSource; Tracker::
  /// trackByFollowing) and detected only when that fails.
  bool follow_keypoints = true;
  /// A frame's followed keypoints are kept when RANSAC keeps at least this share of the keypoints
  /// the chain of followed frames began with (those of the detecting frame that could be followed;
  /// and min_inliers): the chain thins as keypoints leave the view or fail the flow's checks, and
  /// a frame that detects again also finds those of the surface that came into view.
  double follow_min_share = 0.5;
  /// OnDemand: the dense term alone may track a frame whose surface has at least this geometric
  /// stability (geometricStability: lambda_min / lambda_max of its point-to-plane information).
  /// 0.02: the weakest direction at most 7x less certain than the strongest (1 / sqrt(0.02)); a
  /// box seen face-on (< 0.001) or a mug (its twist, 0.003-0.015 with exact normals) stays
  /// below, three faces of a box (0.2) above.
  double min_surface_stability = 0.02;
  /// Paper IV-D's 7 linearisations at most, stopping once no node moves by 0.1 mm nor turns by
  /// 1 mrad (0.1 mm at 10 cm): a tenth of the least noisy sensor's depth spread (1.2 mm at 0.4 m),
  /// the relinearisation cache's own scale below. With PCG's 5 iterations a step never falls to
  /// GaussNewtonSettings' 1e-7, and the 7 linearisations always ran. A hundredth (10 um, 0.1 mrad)
  /// took 3.3 linearisations per frame on the default box and 5.2-6.4 on the shared sequences,
  /// a tenth 2.1 and 3.6-5.1, every cell of the stress matrix within 0.2 ADD-S of it.
  GaussNewtonSettings gauss_newton{.iterations = 7, .min_translation_step = 1e-4, .min_rotation_step = 1e-3};
  /// An edge between two keyframes keeps its linearisation, moved along its linear model, until a
  /// keyframe has moved by max_translation or turned by max_rotation since (EdgeLinearisationCache;
  /// 0: every edge at every step, as the paper). 0.5 mm and 1 mrad move a point 25 cm from the
  /// keyframe's centre by at most 0.75 mm: about the least noisy preset's depth spread at 0.5 m
  /// (active stereo, 0.65 mm) and under a pixel there, so a new association would change few pairs
  /// and the linear model's own error (second order: 1 mrad^2 x 0.25 m = 0.25 um) none. The graph
  /// then linearises the current frame's K edges per step instead of K (K + 1) / 2; on the default
  /// box the frame went from 51 to 18 ms, the stress matrix's cells stayed within 0.2 ADD-S.
  RelinearisationSettings relinearisation{.max_translation = 5e-4, .max_rotation = 1e-3};
};

}  // namespace bundletrack
