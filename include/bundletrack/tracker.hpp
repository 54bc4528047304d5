#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "bundletrack/energy.hpp"
#include "bundletrack/features/correspondence_source.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/graph/keyframe_pool.hpp"
#include "bundletrack/masks/given_masks.hpp"
#include "bundletrack/masks/propagated_masks.hpp"
#include "bundletrack/registration/ransac.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/residuals/feature_point_to_point.hpp"
#include "bundletrack/solvers/dense_ldlt.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"
#include "bundletrack/solvers/pcg.hpp"
#include "bundletrack/tracking/coarse_tracker.hpp"
#include "bundletrack/tracking/stopwatch.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bundletrack {

/// Defaults of DESIGN.md section 3 (the original code's values unless noted).
struct TrackerSettings {
  CoarseTrackerSettings coarse;  ///< RANSAC between consecutive frames and the lost threshold
  std::size_t max_keyframes = 15;  ///< K: keyframes in the pose graph besides the current frame (paper IV-C)
  std::size_t pool_capacity = 200;  ///< keyframes kept in memory (the original pool was unbounded)
  double new_keyframe_rotation_deg = 10.0;  ///< paper IV-E
  int dense_grid_step = 4;  ///< the dense term runs on the image downsampled by this factor
  float edge_gate_distance = 0.02f;  ///< metres; feature matches of an edge must agree with the current poses
  float edge_gate_normal_angle_deg = 45.0f;
  int min_edge_correspondences = 6;  ///< an edge with fewer feature correspondences has no feature term
  /// The optimised pose is kept only when this fraction of the frame's points lies on some other
  /// node's surface (within agreement_distance and 45 degrees); otherwise the coarse pose stands,
  /// or, when RANSAC with the previous frame failed too (textureless or small objects), the frame
  /// is lost. Sensor noise is a few mm at the working range, so a right pose puts nearly every
  /// overlapping point within 1 cm.
  double min_agreement = 0.5;
  float agreement_distance = 0.01f;  ///< metres
  /// RANSAC inliers needed to restart after lost frames (with the last good frame or a keyframe).
  /// Without a motion prior a handful of inliers can be chance: on the synthetic box, 5 of 12
  /// matches gave a pose 172 degrees off; 12 is well above what random matches gather.
  int recovery_min_inliers = 12;
  /// A frame with fewer keypoints than this cannot be re-acquired by features (textureless
  /// objects); after lost frames it is re-acquired by the surface alone: the graph runs from the
  /// last good pose and its result must reach recovery_min_agreement. Twice the inliers a feature
  /// recovery needs.
  int recovery_min_keypoints = 24;
  /// Right poses reach 0.9-1.0 agreement (5th percentile 0.72-0.97 over the synthetic and shared
  /// sequences); a re-acquisition without features has no inlier count behind it, so it must do
  /// better than min_agreement.
  double recovery_min_agreement = 0.8;
  GaussNewtonSettings gauss_newton;
};

/// Paper eq. 1 with lambda_1 = lambda_2 = 1 and Huber losses (delta 5 mm).
using DefaultEnergy = Energy<Term<FeaturePointToPoint, HuberLoss>, Term<DensePointToPlane, HuberLoss>>;

/// BundleTrack (paper IV) composed at compile time from its policies: the pose-graph energy, the
/// linear solver of the Gauss-Newton steps, the correspondence source, the mask source and the
/// robust registration (RANSAC) of the coarse step.
/// Feed frames in order: initialize() with the first, then track() each one; every call returns
/// the pose of that frame, its status, the mask used and per-stage timings, and never changes an
/// earlier answer. With a PropagatedMaskSource only the first frame's mask is read.
template <PoseGraphEnergy EnergyT = DefaultEnergy, LinearSolver Solver = PCG,
          CorrespondenceSource Correspondences = SiftFeatures, MaskSource Masks = GivenMasks,
          FeatureRegistration Registration = Ransac>
class Tracker {
 public:
  using Settings = TrackerSettings;

  explicit Tracker(const PinholeCameraf& camera, Settings settings = Settings(), EnergyT energy = EnergyT(),
                   Solver solver = Solver(), Correspondences correspondences = Correspondences(),
                   Masks masks = Masks())
      : camera_(camera), settings_(settings), energy_(std::move(energy)), solver_(std::move(solver)),
        correspondences_(std::move(correspondences)), masks_(std::move(masks)), ransac_(settings.coarse.ransac),
        pool_(settings.pool_capacity) {}

  static constexpr bool kPropagatedMasks = PropagatedMaskSource<Masks>;

  const KeyframePool& keyframes() const { return pool_; }

  TrackResult initialize(const RgbdFrame& frame, const SE3d& T_cam_obj = {}) {
    Stopwatch watch, total;
    TrackResult result;
    RgbdFrame masked = frame;  // shares the image buffers
    if constexpr (kPropagatedMasks) {
      masks_.start(frame, camera_, T_cam_obj, settings_.dense_grid_step);
    } else {
      masked.mask = masks_.mask(frame);
      if (cv::countNonZero(masked.mask) == 0)
        throw InputError("frame " + frame.name, "the first frame needs a non-empty object mask");
    }
    result.mask = masked.mask;
    result.timings.mask = watch.lap();
    FrameFeatures features = correspondences_.detect(masked);
    result.timings.features = watch.lap();
    pool_ = KeyframePool(settings_.pool_capacity);
    cache_.clear();
    frame_index_ = 0;
    lost_streak_ = 0;
    pool_.add(makeKeyframe(0, masked, masked.mask, features, T_cam_obj, settings_.dense_grid_step));
    result.timings.graph = watch.lap();
    previous_ = Previous{0, T_cam_obj, std::move(features), pool_[0].points};
    result.T_cam_obj = T_cam_obj;
    result.status = TrackStatus::Tracked;
    result.keypoints = int(previous_->features.size());
    result.timings.total = total.lap();
    return result;
  }

  TrackResult track(const RgbdFrame& frame) {
    if (!previous_) throw InputError("frame " + frame.name, "track() called before initialize()");
    Stopwatch watch, total;
    TrackResult result;
    const int id = ++frame_index_;
    const bool recovering = lost_streak_ > 0;
    RgbdFrame masked = frame;  // shares the image buffers
    // Propagated masks: keypoints are searched around the object at its last pose, or everywhere
    // after it was lost; the mask itself follows from the coarse pose below.
    if constexpr (kPropagatedMasks)
      masked.mask = masks_.searchRegion(frame, observedObject(previous_->T_cam_obj),
                                        recovering ? std::nullopt : std::optional(previous_->T_cam_obj));
    else
      masked.mask = result.mask = masks_.mask(frame);
    result.timings.mask = watch.lap();
    if (cv::countNonZero(masked.mask) == 0) return lost(result, total);  // the object is out of sight
    FrameFeatures features = correspondences_.detect(masked);
    result.timings.features = watch.lap();
    result.keypoints = int(features.size());

    // Coarse pose from the previous good frame (paper IV-B).
    const auto matches = correspondences_.match(previous_->features, features, std::nullopt);
    result.timings.matching += watch.lap();
    const RansacResult coarse = ransac_.estimate(previous_->features, features, matches);
    result.timings.ransac += watch.lap();
    result.matches = int(matches.size());
    result.inliers = int(coarse.inliers.size());
    // Re-acquisition after lost frames: the object may come back anywhere, a geometric check alone
    // accepts symmetric wrong poses (a box turned by 90 degrees), and a few inliers happen by
    // chance; so the track restarts only from a feature match with recovery_min_inliers inliers,
    // with the previous good frame or else with a keyframe, that the graph then confirms.
    const int needed = recovering ? settings_.recovery_min_inliers : settings_.coarse.min_inliers;
    const bool previous_ok = result.inliers >= needed;
    bool coarse_ok = previous_ok;
    SE3d T_coarse = coarse_ok ? coarse.T_second_first * previous_->T_cam_obj : previous_->T_cam_obj;
    bool by_surface = false;  // re-acquisition of a texture-poor frame by the graph alone
    if (recovering && !coarse_ok) {
      if (const auto recovered = matchKeyframes(features, result.timings, watch)) {
        T_coarse = *recovered;
        coarse_ok = true;
      } else if (int(features.size()) < settings_.recovery_min_keypoints) {
        by_surface = true;  // from the last good pose
      } else {
        return lost(result, total);
      }
    }
    std::vector<FeatureMatch> previous_inliers = previous_ok ? inlierMatches(matches, coarse.inliers) : std::vector<FeatureMatch>();
    if constexpr (kPropagatedMasks) {
      masked.mask = result.mask = masks_.mask(frame, observedObject(T_coarse), T_coarse);
      result.timings.mask += watch.lap();
      if (cv::countNonZero(masked.mask) == 0) return lost(result, total);  // not where the pose says
      const std::vector<int> kept = keepFeaturesInside(features, masked.mask);
      std::vector<FeatureMatch> remapped;
      for (const FeatureMatch& m : previous_inliers)
        if (const int second = kept[std::size_t(m.second)]; second >= 0) remapped.push_back({m.first, second});
      previous_inliers = std::move(remapped);
    }

    // Pose graph over the selected keyframes and the current frame (paper IV-C, IV-D).
    Keyframe current =
        makeKeyframe(id, masked, masked.mask, std::move(features), T_coarse, settings_.dense_grid_step);
    // Ascending ids put frame 0 first (the fixed node) and give every keyframe pair one orientation.
    std::vector<std::size_t> selected = pool_.select(T_coarse.rotation(), settings_.max_keyframes);
    std::sort(selected.begin(), selected.end());
    std::vector<const Keyframe*> nodes;
    std::vector<SE3d> poses;
    for (const std::size_t k : selected) nodes.push_back(&pool_[k]), poses.push_back(pool_[k].T_cam_obj);
    nodes.push_back(&current);
    poses.push_back(T_coarse);
    result.timings.graph += watch.lap();

    std::vector<std::vector<FeatureMatch>> current_matches(nodes.size());
    std::vector<GraphEdge> edges;
    const int last = int(nodes.size()) - 1;
    for (int a = 0; a < last; ++a) {
      for (int b = a + 1; b <= last; ++b) {
        const std::vector<FeatureMatch>* edge_matches;
        if (b == last) {
          if (nodes[a]->id == previous_->id && previous_ok) current_matches[a] = std::move(previous_inliers);
          else current_matches[a] = edgeCorrespondences(*nodes[a], current, poses[a], poses[b], result.timings, watch);
          edge_matches = &current_matches[a];
        } else {
          edge_matches = &cachedCorrespondences(*nodes[a], *nodes[b], result.timings, watch);
        }
        edges.push_back({a, b, edge_matches});
      }
    }
    result.timings.graph += watch.lap();
    // Unlike the original code, the graph runs even when the frame has no feature edge: the dense
    // term alone often holds the pose. The result is verified against the nodes' surfaces; when it
    // fails, the coarse pose stands (or the frame is lost when there is none).
    optimizePoseGraph(energy_, solver_, nodes, edges, downsampledCamera(camera_, settings_.dense_grid_step), poses,
                      settings_.gauss_newton);
    if (agreement(nodes, poses) >= (by_surface ? settings_.recovery_min_agreement : settings_.min_agreement)) {
      for (std::size_t n = 0; n < selected.size(); ++n) pool_[selected[n]].T_cam_obj = poses[n];
      result.T_cam_obj = poses.back();
      result.status = TrackStatus::Tracked;
    } else if (coarse_ok && !recovering) {
      result.T_cam_obj = T_coarse;
      result.status = TrackStatus::CoarseOnly;
    } else {
      return lost(result, total);
    }
    result.timings.solve = watch.lap();
    if constexpr (kPropagatedMasks) {
      // The mask came from the coarse pose (the last pose when RANSAC failed); what the tracker
      // keeps of this frame (a keyframe, the next frame's rendering) is cut with the final pose.
      const cv::Mat refined = masks_.mask(frame, observedObject(result.T_cam_obj), result.T_cam_obj);
      if (cv::countNonZero(refined) > 0) {
        masked.mask = result.mask = refined;
        keepFeaturesInside(current.features, refined);
        current = makeKeyframe(id, masked, refined, std::move(current.features), result.T_cam_obj,
                               settings_.dense_grid_step);
      }
      result.timings.mask += watch.lap();
    }

    // Paper IV-E: keep the frame when it shows a novel view (a copy only then: the graph is done,
    // and the features move on to the next frame's coarse step).
    current.T_cam_obj = result.T_cam_obj;
    if (result.status == TrackStatus::Tracked &&
        pool_.isNovelView(result.T_cam_obj.rotation(), settings_.new_keyframe_rotation_deg * std::numbers::pi / 180.0)) {
      if (const int evicted = pool_.add(current); evicted >= 0) forget(evicted);
    }
    previous_ = Previous{id, result.T_cam_obj, std::move(current.features), current.points};
    lost_streak_ = 0;
    result.timings.graph += watch.lap();
    result.timings.total = total.lap();
    return result;
  }

 private:
  struct Previous {
    int id;
    SE3d T_cam_obj;
    FrameFeatures features;
    cv::Mat points;  ///< its object points on the dense grid
  };

  /// What the tracker has seen of the object, for propagated masks: the previous good frame and
  /// the keyframes the graph would pick for this pose.
  std::vector<ObservedSurface> observedObject(const SE3d& T_cam_obj) const {
    std::vector<ObservedSurface> object{{previous_->points, previous_->T_cam_obj}};
    for (const std::size_t k : pool_.select(T_cam_obj.rotation(), settings_.max_keyframes))
      object.push_back({pool_[k].points, pool_[k].T_cam_obj});
    return object;
  }

  TrackResult& lost(TrackResult& result, Stopwatch& total) {
    ++lost_streak_;
    result.T_cam_obj = previous_->T_cam_obj;
    result.status = TrackStatus::Lost;
    result.timings.total = total.lap();
    return result;
  }

  /// Matches the frame against the pool's keyframes, nearest in rotation to the last good pose
  /// first (at most max_keyframes of them), and returns the pose from the keyframe with the most
  /// RANSAC inliers, when it has at least recovery_min_inliers.
  std::optional<SE3d> matchKeyframes(const FrameFeatures& features, StageTimings& timings, Stopwatch& watch) {
    std::vector<std::size_t> order(pool_.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    const SO3d last = previous_->T_cam_obj.rotation();
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return rotationGeodesic(pool_[a].T_cam_obj.rotation(), last) < rotationGeodesic(pool_[b].T_cam_obj.rotation(), last);
    });
    order.resize(std::min(order.size(), settings_.max_keyframes));
    std::optional<SE3d> best;
    int best_inliers = settings_.recovery_min_inliers - 1;
    for (const std::size_t k : order) {
      const auto matches = correspondences_.match(pool_[k].features, features, std::nullopt);
      timings.matching += watch.lap();
      const RansacResult ransac = ransac_.estimate(pool_[k].features, features, matches);
      timings.ransac += watch.lap();
      if (int(ransac.inliers.size()) > best_inliers) {
        best_inliers = int(ransac.inliers.size());
        best = ransac.T_second_first * pool_[k].T_cam_obj;
      }
    }
    return best;
  }

  /// Of the last node's grid points that land on a valid point of another node, the fraction
  /// that lies on that node's surface under the given poses (projective association,
  /// agreement_distance, 45 degrees). Grids have holes (depth dropouts, undefined normals), so points
  /// landing in a hole say nothing; when fewer than a quarter of the points land anywhere the
  /// answer is 0.
  double agreement(const std::vector<const Keyframe*>& nodes, const std::vector<SE3d>& poses) const {
    const Keyframe& current = *nodes.back();
    const PinholeCameraf grid = downsampledCamera(camera_, settings_.dense_grid_step);
    const double cos_max = std::cos(double(settings_.edge_gate_normal_angle_deg) * std::numbers::pi / 180.0);
    const double max_sq = double(settings_.agreement_distance) * double(settings_.agreement_distance);
    std::vector<SE3d> T_k_c;
    for (std::size_t k = 0; k + 1 < nodes.size(); ++k) T_k_c.push_back(poses[k] * poses.back().inverse());
    int valid = 0, compared = 0, agreeing = 0;
    for (int y = 0; y < current.points.rows; ++y) {
      for (int x = 0; x < current.points.cols; ++x) {
        const cv::Vec3f& pc = current.points.at<cv::Vec3f>(y, x);
        if (pc[2] <= 0.0f) continue;
        ++valid;
        const Eigen::Vector3d p(pc[0], pc[1], pc[2]);
        const cv::Vec3f& nc = current.normals.at<cv::Vec3f>(y, x);
        bool landed = false, agrees = false;
        for (std::size_t k = 0; k < T_k_c.size() && !agrees; ++k) {
          const Eigen::Vector3d q = T_k_c[k] * p;
          if (q.z() <= 0.0) continue;
          const int u = int(std::lround(grid.fx * q.x() / q.z() + grid.cx));
          const int v = int(std::lround(grid.fy * q.y() / q.z() + grid.cy));
          if (u < 0 || v < 0 || u >= nodes[k]->points.cols || v >= nodes[k]->points.rows) continue;
          const cv::Vec3f& pk = nodes[k]->points.at<cv::Vec3f>(v, u);
          if (pk[2] <= 0.0f) continue;
          landed = true;
          const cv::Vec3f& nk = nodes[k]->normals.at<cv::Vec3f>(v, u);
          const Eigen::Vector3d n = T_k_c[k].rotation() * Eigen::Vector3d(nc[0], nc[1], nc[2]);
          agrees = (Eigen::Vector3d(pk[0], pk[1], pk[2]) - q).squaredNorm() <= max_sq &&
                   n.dot(Eigen::Vector3d(nk[0], nk[1], nk[2])) >= cos_max;
        }
        compared += landed;
        agreeing += agrees;
      }
    }
    if (compared == 0 || 4 * compared < valid) return 0.0;
    return double(agreeing) / double(compared);
  }

  static std::vector<FeatureMatch> inlierMatches(const std::vector<FeatureMatch>& matches, const std::vector<int>& inliers) {
    std::vector<FeatureMatch> out;
    for (const int k : inliers) out.push_back(matches[std::size_t(k)]);
    return out;
  }

  /// Feature correspondences of an edge (paper IV-D): matches gated by the current poses (2 cm,
  /// 45 degrees), pruned by RANSAC; fewer than min_edge_correspondences count as none.
  std::vector<FeatureMatch> edgeCorrespondences(const Keyframe& a, const Keyframe& b, const SE3d& T_a, const SE3d& T_b,
                                                StageTimings& timings, Stopwatch& watch) {
    const MatchGate gate{(T_b * T_a.inverse()).cast<float>(), settings_.edge_gate_distance,
                         settings_.edge_gate_normal_angle_deg};
    const auto matches = correspondences_.match(a.features, b.features, gate);
    timings.matching += watch.lap();
    const RansacResult pruned = ransac_.estimate(a.features, b.features, matches);
    timings.ransac += watch.lap();
    if (int(pruned.inliers.size()) < settings_.min_edge_correspondences) return {};
    return inlierMatches(matches, pruned.inliers);
  }

  /// Keyframe pairs are matched once (paper IV-D: "if C_ij has been built ... it is reused").
  const std::vector<FeatureMatch>& cachedCorrespondences(const Keyframe& a, const Keyframe& b, StageTimings& timings,
                                                         Stopwatch& watch) {
    const auto key = std::make_pair(a.id, b.id);
    auto found = cache_.find(key);
    if (found == cache_.end())
      found = cache_.emplace(key, edgeCorrespondences(a, b, a.T_cam_obj, b.T_cam_obj, timings, watch)).first;
    return found->second;
  }

  void forget(int keyframe_id) {
    for (auto it = cache_.begin(); it != cache_.end();)
      it = it->first.first == keyframe_id || it->first.second == keyframe_id ? cache_.erase(it) : std::next(it);
  }

  PinholeCameraf camera_;
  Settings settings_;
  EnergyT energy_;
  Solver solver_;
  Correspondences correspondences_;
  Masks masks_;
  Registration ransac_;
  KeyframePool pool_;
  std::map<std::pair<int, int>, std::vector<FeatureMatch>> cache_;
  std::optional<Previous> previous_;
  int frame_index_ = 0;
  int lost_streak_ = 0;  ///< frames lost since the last good one
};

using DefaultTracker = Tracker<>;

}  // namespace bundletrack
