#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/error.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/start_frame_check.hpp"
#include "bundletrack/energy.hpp"
#include "bundletrack/features/correspondence_source.hpp"
#include "bundletrack/graph/keyframe_pool.hpp"
#include "bundletrack/graph/pose_graph_builder.hpp"
#include "bundletrack/graph/relocalisation.hpp"
#include "bundletrack/masks/mask_source.hpp"
#include "bundletrack/registration/feature_registration.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"
#include "bundletrack/solvers/linear_solver.hpp"
#include "bundletrack/tracking/frame_context.hpp"
#include "bundletrack/tracking/stage_clock.hpp"
#include "bundletrack/tracking/tracker_settings.hpp"
#include "bundletrack/verification/geometric_stability.hpp"
#include "bundletrack/verification/pose_verifier.hpp"

namespace bundletrack {

/// BundleTrack (paper IV) composed at compile time from its policies: the pose-graph energy, the
/// linear solver of its Gauss-Newton steps, the correspondence source, the mask source, the
/// robust registration of the coarse step and the verification of the optimised pose.
/// bundletrack/default_tracker.hpp names the paper's choices (DefaultTracker).
/// Feed frames in order: initialize() with the first, then track() each one; every call returns
/// the pose of that frame, its status, the mask used and per-stage timings, and never changes an
/// earlier answer.
template <PoseGraphEnergy EnergyT, LinearSolver Solver, CorrespondenceSource Correspondences, MaskSource Masks,
          FeatureRegistration Registration, PoseVerifier Verifier>
class Tracker {
 public:
  using Settings = TrackerSettings;

  explicit Tracker(const PinholeCameraf& camera, Settings settings = Settings(), EnergyT energy = EnergyT(),
                   Solver solver = Solver(), Correspondences correspondences = Correspondences(),
                   Masks masks = Masks(), Registration registration = Registration(), Verifier verifier = Verifier())
      : camera_(camera), settings_(settings), energy_(std::move(energy)), solver_(std::move(solver)),
        correspondences_(std::move(correspondences)), masks_(std::move(masks)),
        registration_(std::move(registration)), verifier_(std::move(verifier)), pool_(settings.pool_capacity) {}

  const KeyframePool& keyframes() const { return pool_; }

  /// The part of the next frame's image the tracker will read depth from (pass it to makeFrame:
  /// only that part is then preprocessed): the mask source's region (GivenMasks: the box of
  /// `given_mask`, the frame's mask from the data; PropagatedMasks: around the last pose's
  /// silhouette) grown by kRegionMargin; the whole image before initialize() and after a loss
  /// without a given mask.
  cv::Rect regionOfInterest(cv::Size image, const cv::Mat& given_mask = {}) const {
    if (!last_) return cv::Rect({0, 0}, image);
    const std::optional<SE3d> guess = lost_streak_ > 0 ? std::nullopt : std::optional(last_->T_cam_obj);
    return grownWithin(masks_.regionOfInterest(image, given_mask, observed(), guess), kRegionMargin, image);
  }

  /// Starts the track: the first frame with its mask and pose is keyframe 0, the graph's fixed node.
  /// A frame without depth under its mask, or a pose it contradicts, is refused (checkStartFrame).
  TrackResult initialize(const RgbdFrame& frame, const SE3d& T_cam_obj = {}) {
    checkStartFrame(frame, T_cam_obj);
    clock_.start(&StageTimings::mask);
    TrackResult result;
    RgbdFrame masked = frame;  // shares the image buffers
    masked.mask = masks_.frameMask(frame);
    grid_step_ = masked.mask.empty() ? settings_.dense_grid_step
                                     : gridStepFor(masked, masked.mask, settings_.dense_target_samples, settings_.dense_grid_step);
    masked.mask = result.mask = masks_.start(masked, camera_, T_cam_obj, grid_step_);
    clock_.enter(&StageTimings::features);
    FrameFeatures features = correspondences_.detect(masked);
    clock_.enter(&StageTimings::graph);
    pool_ = KeyframePool(settings_.pool_capacity);
    cache_.clear();
    linearisations_ = EdgeLinearisationCache(settings_.relinearisation);
    frame_index_ = 0;
    lost_streak_ = 0;
    pool_.add(keyframeOf(0, masked, masked.mask, features, T_cam_obj));
    result.keypoints = int(features.size());
    cv::Mat gray;
    if (followsKeypoints()) cv::cvtColor(frame.color, gray, cv::COLOR_BGR2GRAY);
    last_ = LastGood{0, T_cam_obj, pool_[0].surface, keypointFrame(0, T_cam_obj, std::move(features), gray, masked.mask, 0)};
    result.T_cam_obj = T_cam_obj;
    result.status = TrackStatus::Tracked;
    result.timings = clock_.stop();
    return result;
  }

  /// Paper IV, one frame: segment, keypoints, coarse pose from the last good frame (IV-B), pose
  /// graph over the selected keyframes (IV-C, IV-D), verification, keyframe admission (IV-E).
  /// With keypoints on demand the graph first runs without the frame's keypoints.
  TrackResult track(const RgbdFrame& given) {
    if (!last_) throw InputError("frame " + given.name, "track() called before initialize()");
    clock_.start(&StageTimings::mask);
    RgbdFrame frame = given;  // shares the image buffers; the mask as the source reads it
    frame.mask = masks_.frameMask(given);
    FrameContext ctx(frame, ++frame_index_, lost_streak_ > 0);
    if (!searchObject(ctx)) return lost(ctx);  // the object is out of sight
    if (!trackBySurface(ctx) && !trackByFollowing(ctx)) {
      detectKeypoints(ctx);
      const FrameFeatures detected = ctx.features;  // the candidates below may cut them to their masks
      if (!estimateCoarsePose(ctx)) return lost(ctx);
      if (!refineCoarsePose(ctx) && !refineFromFollowing(ctx) && !reacquireAtOnce(ctx, detected)) return lost(ctx);
    }
    cutMaskWithFinalPose(ctx);
    admitKeyframe(ctx);
    ctx.result.timings = clock_.stop();
    return std::move(ctx.result);
  }

 private:
  /// A frame's keypoints with the frame's id and pose, and what following them needs: the frame's
  /// grey image (empty when the correspondence source cannot follow) and object mask, and, for
  /// followed keypoints, how many the chain of followed frames began with (0: detected here).
  struct KeypointFrame {
    int id;
    SE3d T_cam_obj;
    FrameFeatures features;
    cv::Mat gray;
    cv::Mat mask;
    int chain_start = 0;
  };

  /// Whether the next frame may follow this one's keypoints: the source can follow and following is on.
  bool followsKeypoints() const {
    return FollowingSource<Correspondences> && settings_.keypoints == KeypointSchedule::OnDemand && settings_.follow_keypoints;
  }

  /// A frame's keypoints as the next frame may follow them: with the frame's grey image (`gray`,
  /// made by grayOf) and a copy of its mask (the caller may reuse its buffers for the next frame)
  /// where followsKeypoints().
  KeypointFrame keypointFrame(int id, const SE3d& T_cam_obj, FrameFeatures features, const cv::Mat& gray,
                              const cv::Mat& mask, int chain_start) const {
    KeypointFrame keypoints{id, T_cam_obj, std::move(features), {}, {}, chain_start};
    if (followsKeypoints()) {
      keypoints.gray = gray;
      keypoints.mask = mask.clone();
    }
    return keypoints;
  }

  /// The frame's grey image, made once per frame where followsKeypoints() (else empty).
  const cv::Mat& grayOf(FrameContext& ctx) const {
    if (ctx.gray.empty() && followsKeypoints()) cv::cvtColor(ctx.frame.color, ctx.gray, cv::COLOR_BGR2GRAY);
    return ctx.gray;
  }

  /// What the next frame is tracked from: the last frame that was not lost, and the last good
  /// frame whose keypoints were detected (the same frame unless keypoints are detected on demand).
  struct LastGood {
    int id;
    SE3d T_cam_obj;
    SurfaceGrid surface;
    KeypointFrame keypoints;
  };

  ObservedObject observed() const {
    return ObservedObject({last_->surface.points, last_->T_cam_obj}, pool_, settings_.max_keyframes);
  }

  /// The last good pose as a coarse pose, with nothing but the surface behind it.
  CoarseEstimate fromLastGoodPose() const { return {last_->T_cam_obj, false, false, Evidence::SurfaceOnly, {}}; }

  /// Keypoints are searched where the object was last seen, or anywhere after it was lost.
  bool searchObject(FrameContext& ctx) {
    const std::optional<SE3d> guess = ctx.recovering ? std::nullopt : std::optional(last_->T_cam_obj);
    ctx.masked.mask = masks_.searchRegion(ctx.frame, observed(), guess);
    return cv::countNonZero(ctx.masked.mask) > 0;
  }

  void detectKeypoints(FrameContext& ctx) {
    clock_.enter(&StageTimings::features);
    ctx.features = correspondences_.detect(ctx.masked);
    ctx.keypoints_detected = true;
    ctx.result.keypoints = int(ctx.features.size());
  }

  /// Keypoints on demand (KeypointSchedule::OnDemand): the graph from the last good pose with the
  /// dense term alone for the frame's edges. Its result is kept when the surface under that pose
  /// holds every direction of the motion (geometricStability at least min_surface_stability) and
  /// the verifier accepts it on surface evidence; otherwise the frame starts over with keypoints,
  /// from its search region. Not after lost frames.
  bool trackBySurface(FrameContext& ctx) {
    if (settings_.keypoints != KeypointSchedule::OnDemand || ctx.recovering) return false;
    const cv::Mat search_region = ctx.masked.mask;
    ctx.coarse = fromLastGoodPose();
    if (segmentObject(ctx) && geometricStability(makeNode(ctx).surface) >= settings_.min_surface_stability) {
      buildGraph(ctx);
      optimiseGraph(ctx);
      if (acceptPose(ctx)) return ctx.result.surface_only = true;
    }
    ctx.masked.mask = search_region;
    ctx.result.mask = cv::Mat();
    return false;
  }

  /// Keypoints on demand, where the surface alone cannot hold the frame: the keypoints of the last
  /// good frame, when it has its own (detected or followed), are followed into this frame by
  /// optical flow (FollowingSource), RANSAC on those pairs gives the coarse pose (paper IV-B), and
  /// the graph runs as with detected keypoints. Kept when RANSAC keeps follow_min_share of the
  /// keypoints the chain of followed frames began with (and min_inliers) and the verifier accepts the
  /// graph's pose; otherwise the frame starts over, detecting keypoints, from its search region,
  /// with following's pose in reserve where RANSAC kept min_inliers (refineFromFollowing).
  bool trackByFollowing(FrameContext& ctx) {
    const KeypointFrame& last = last_->keypoints;
    if (!settings_.follow_keypoints || settings_.keypoints != KeypointSchedule::OnDemand || ctx.recovering ||
        last.id != last_->id || last.gray.empty())
      return false;
    clock_.enter(&StageTimings::features);
    FollowedFeatures followed;
    if constexpr (FollowingSource<Correspondences>)
      followed = correspondences_.follow(last.gray, last.mask, last.features, ctx.masked, grayOf(ctx));
    const auto estimate = clock_.measure(&StageTimings::ransac, [&] {
      return registration_.estimate(last.features, followed.features, followed.matches);
    });
    const int chain_start = last.chain_start > 0 ? last.chain_start : followed.tried;
    const int needed = std::max(settings_.min_inliers, int(std::ceil(settings_.follow_min_share * chain_start)));
    CoarseEstimate coarse{estimate.T_second_first * last.T_cam_obj, true, true, Evidence::Features, {}};
    for (const int k : estimate.inliers) coarse.last_inliers.push_back(followed.matches[std::size_t(k)]);
    if (int(estimate.inliers.size()) < needed) {
      if (int(estimate.inliers.size()) >= settings_.min_inliers)
        ctx.followed_reserve = FollowedReserve{std::move(followed.features), std::move(coarse)};
      return false;
    }
    const cv::Mat search_region = ctx.masked.mask;
    ctx.features = std::move(followed.features);
    const bool graph_built = optimiseFrom(ctx, coarse, nullptr);
    if (graph_built && acceptPose(ctx) && ctx.result.status == TrackStatus::Tracked) {
      ctx.keypoints_followed = true;
      ctx.chain_start = chain_start;
      ctx.result.followed = int(ctx.current.features.size());
      ctx.result.matches = int(followed.matches.size());
      ctx.result.inliers = int(estimate.inliers.size());
      return true;
    }
    if (graph_built) ctx.followed_reserve = FollowedReserve{std::move(ctx.current.features), ctx.coarse};  // both cut to its mask
    ctx.masked.mask = search_region;
    ctx.result.mask = cv::Mat();
    ctx.result.status = TrackStatus::Lost;
    ctx.features = FrameFeatures();
    return false;
  }

  /// Matches two frames' features (gated when their relative pose is known) and registers them,
  /// charging the two steps to their stages on `clock` where one is given (none: the call may run
  /// beside others, see buildGraph).
  struct PairRegistration {
    std::vector<FeatureMatch> matches;
    std::vector<FeatureMatch> inliers;
    SE3d T_second_first;
  };
  PairRegistration registerPair(const FrameFeatures& first, const FrameFeatures& second, const std::optional<MatchGate>& gate,
                                StageClock* clock) const {
    const auto timed = [clock](Stage stage, auto&& step) { return clock ? clock->measure(stage, step) : step(); };
    PairRegistration pair;
    pair.matches = timed(&StageTimings::matching, [&] { return correspondences_.match(first, second, gate); });
    const auto estimate = timed(&StageTimings::ransac, [&] { return registration_.estimate(first, second, pair.matches); });
    for (const int k : estimate.inliers) pair.inliers.push_back(pair.matches[std::size_t(k)]);
    pair.T_second_first = estimate.T_second_first;
    return pair;
  }

  /// Paper IV-B: RANSAC with the last good frame; after lost frames, the candidates of
  /// reacquisitionCandidates. Where no pose is found with the last frame, the graph starts from
  /// the last good pose with nothing but the surface behind it, and is verified as such (as by
  /// trackBySurface, which may have refused the same graph already); the detected keypoints are
  /// also kept aside for refineFromFollowing.
  bool estimateCoarsePose(FrameContext& ctx) {
    const KeypointFrame& last = last_->keypoints;
    PairRegistration from_last = registerPair(last.features, ctx.features, std::nullopt, &clock_);
    ctx.result.matches = int(from_last.matches.size());
    ctx.result.inliers = int(from_last.inliers.size());
    if (ctx.recovering) return reacquisitionCandidates(ctx, std::move(from_last));
    if (ctx.result.inliers < settings_.min_inliers) {
      if (ctx.followed_reserve) ctx.detected_kept = ctx.features;
      ctx.candidates.push_back(fromLastGoodPose());
      return true;
    }
    ctx.candidates.push_back({from_last.T_second_first * last.T_cam_obj, true, true, Evidence::Features, std::move(from_last.inliers)});
    // A registration on fewer inliers than chance can gather may be wrong (a small mug 3 m away:
    // 8 of 8 matches kept, turned by 140 degrees): where the keyframes' surfaces refuse the graph
    // from it, the graph from the last good pose is tried on the surface's evidence before
    // RANSAC's pose is reported.
    if (ctx.result.inliers < settings_.recovery_min_inliers)
      ctx.candidates.push_back(fromLastGoodPose());
    return true;
  }

  /// After lost frames the object may come back anywhere, a geometric check alone accepts
  /// symmetric wrong poses (a box turned by 90 degrees) and a few inliers happen by chance. So a
  /// registration with recovery_min_inliers inliers -- with the last good frame, or else with a
  /// keyframe -- is tried on its features' evidence; the other candidates (at most
  /// recovery_surface_candidates: registrations with min_inliers or more, the last good pose,
  /// and that pose moved onto the object's points now) must pass the verifier's test for a pose
  /// with the surface alone behind it.
  bool reacquisitionCandidates(FrameContext& ctx, PairRegistration from_last) {
    // Registrations with enough inliers, most first (the last good frame's first among equals).
    std::vector<std::pair<int, CoarseEstimate>> registered;
    const int last_inliers = ctx.result.inliers;
    if (last_inliers >= settings_.min_inliers)
      registered.push_back({last_inliers, {from_last.T_second_first * last_->keypoints.T_cam_obj, true, true, Evidence::Features,
                                           std::move(from_last.inliers)}});
    if (last_inliers < settings_.recovery_min_inliers) {
      for (const RelocalisedPose& pose :
           relocalise(pool_, last_->T_cam_obj.rotation(), settings_.max_keyframes, settings_.min_inliers,
                      [&](const Keyframe& keyframe) { return registerPair(keyframe.features, ctx.features, std::nullopt, &clock_); }))
        registered.push_back({pose.inliers, {pose.T_cam_obj, true, false, Evidence::Features, {}}});
      std::stable_sort(registered.begin(), registered.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
    }
    std::vector<CoarseEstimate> by_surface;
    for (auto& [inliers, coarse] : registered) {
      if (inliers >= settings_.recovery_min_inliers && ctx.candidates.empty()) {
        ctx.candidates.push_back(std::move(coarse));
      } else {
        coarse.evidence = Evidence::SurfaceOnly;
        by_surface.push_back(std::move(coarse));
      }
    }
    by_surface.push_back(fromLastGoodPose());
    const std::optional<Placement> moved = movedOntoObject(ctx.masked);
    if (moved) by_surface.push_back({moved->T_cam_obj, false, false, Evidence::SurfaceOnly, {}});
    by_surface.resize(std::min(by_surface.size(), std::size_t(std::max(0, settings_.recovery_surface_candidates))));
    if (moved && !by_surface.empty())
      for (const SE3d& turned : turnedAbout(moved->T_cam_obj, moved->centroid, radians(settings_.recovery_turn_step_deg),
                                            settings_.recovery_turn_rings))
        by_surface.push_back({turned, false, false, Evidence::SurfaceOnly, {}});
    for (CoarseEstimate& coarse : by_surface) ctx.candidates.push_back(std::move(coarse));
    return !ctx.candidates.empty();
  }

  /// A frame whose every candidate above was refused is not given up while the object may be in
  /// view: the candidates of a re-acquisition (reacquisitionCandidates: keyframe registrations,
  /// the last good pose moved onto the object's points and turned about them, decided together)
  /// are tried on it at once, from the search region of a lost track, rather than on the next
  /// frame. A jump the graph from the last good pose cannot follow (a small object moving fast)
  /// then costs no frame; a frame without the object is lost as before. The object was at its
  /// last good pose a frame ago, so a pose the surface alone holds must lie within the
  /// candidates' reach of it (withinReach).
  bool reacquireAtOnce(FrameContext& ctx, FrameFeatures detected) {
    if (ctx.recovering) return false;  // those candidates were this frame's already
    ctx.recovering = ctx.reacquiring_at_once = true;
    ctx.features = std::move(detected);
    ctx.candidates.clear();
    return searchObject(ctx) && estimateCoarsePose(ctx) && refineCoarsePose(ctx);
  }

  /// A pose placed on the points of a frame, and their centroid (camera frame).
  struct Placement {
    SE3d T_cam_obj;
    Eigen::Vector3d centroid;
  };

  /// A coarse geometric search: the last good pose translated by the offset between the centroid of
  /// the last good frame's object points and that of the points in this frame's search region;
  /// none when the region holds no points or is far larger than the object (it is not the object).
  std::optional<Placement> movedOntoObject(const RgbdFrame& masked) const {
    const SurfaceGrid& seen = last_->surface;
    if (seen.cells.empty()) return std::nullopt;
    const Eigen::Vector3d before = spreadOf(seen).centroid;
    Eigen::Vector3d now = Eigen::Vector3d::Zero();
    const int step = grid_step_;
    int count = 0;
    for (int v = 0; v < masked.mask.rows; v += step) {
      for (int u = 0; u < masked.mask.cols; u += step) {
        const cv::Vec3f& p = masked.points.at<cv::Vec3f>(v, u);
        if (!masked.mask.at<uchar>(v, u) || p[2] <= 0.0f) continue;
        now += Eigen::Vector3d(p[0], p[1], p[2]);
        ++count;
      }
    }
    if (count == 0 || count > 2 * int(seen.cells.size())) return std::nullopt;
    now /= double(count);
    return Placement{SE3d(SO3d(), now - before) * last_->T_cam_obj, now};
  }

  /// Paper IV-C to IV-E's checks on each coarse pose in turn (segment under it, build and optimise
  /// the graph, verify); the first accepted result is the frame's, and where none is, RANSAC's
  /// pose (the first candidate's, CoarseOnly) unless the track is being re-acquired. After lost
  /// frames the candidates with the surface alone behind them are all optimised and decided
  /// together (TrackerSettings::recovery_min_consensus).
  bool refineCoarsePose(FrameContext& ctx) {
    const bool several = ctx.recovering || ctx.candidates.size() > 1;  // tries that need the features again
    const FrameFeatures detected = several ? ctx.features : FrameFeatures();
    const FrameFeatures* features = several ? &detected : nullptr;
    std::vector<SE3d> reached;  // by surface-only candidates the verifier's min_agreement admits ...
    std::vector<std::size_t> reached_from;  // ... and from which
    std::optional<std::size_t> first_confirmed;  // the first that passes the SurfaceOnly test
    bool first_placed = false;  // the first candidate's mask is not empty
    for (std::size_t k = 0; k < ctx.candidates.size(); ++k) {
      const bool placed = optimiseFrom(ctx, ctx.candidates[k], features);
      if (k == 0) first_placed = placed;
      if (!placed) continue;
      if (!ctx.recovering || ctx.coarse.evidence != Evidence::SurfaceOnly) {
        if (takeGraphPose(ctx)) return true;
        continue;
      }
      if (!withinReach(ctx)) continue;
      if (verifier_.accepts(ctx.graph, Evidence::SurfaceConsensus)) {
        reached.push_back(ctx.graph.poses.back());
        reached_from.push_back(k);
      }
      if (!first_confirmed && verifier_.accepts(ctx.graph, Evidence::SurfaceOnly)) first_confirmed = k;
    }
    if (!ctx.recovering) {  // RANSAC's pose, the first candidate's, where every graph was refused
      const bool placed = ctx.candidates.size() == 1 ? first_placed : placeAt(ctx, ctx.candidates.front(), features);
      return placed && takeCoarsePose(ctx);
    }
    const double distance =
        reached.empty() ? 0.0 : ctx.frame.noise.widen(settings_.recovery_consensus_distance, float(reached[0].translation().z()));
    const std::vector<std::size_t> consensus =
        largestConsensus(reached, radians(settings_.recovery_consensus_angle_deg), distance);
    CoarseEstimate chosen;
    if (int(consensus.size()) >= std::max(1, settings_.recovery_min_consensus)) {
      chosen = ctx.candidates[reached_from[consensus[0]]];
      chosen.evidence = Evidence::SurfaceConsensus;
    } else if (first_confirmed) {
      chosen = ctx.candidates[*first_confirmed];
    } else {
      return false;
    }
    return optimiseFrom(ctx, chosen, features) && acceptPose(ctx);
  }

  /// Whether the graph's pose of a frame re-acquired at once lies within the candidates' reach:
  /// turned from the last good pose by no more than the outermost turned start
  /// (recovery_turn_rings x recovery_turn_step_deg). A surface-only graph that ends farther away
  /// has left the search (a 10 cm mug 3 m away, whose surface holds no turn, was taken upside
  /// down); after lost frames the object may come back turned any way, and every pose counts.
  bool withinReach(const FrameContext& ctx) const {
    return !ctx.reacquiring_at_once ||
           rotationGeodesic(ctx.graph.poses.back().rotation(), last_->T_cam_obj.rotation()) <=
               radians(settings_.recovery_turn_step_deg * settings_.recovery_turn_rings);
  }

  /// The graph of the current frame from one coarse pose (false: the object is not where it says),
  /// with the frame's `features` when given (else those in ctx, which move into the node).
  bool optimiseFrom(FrameContext& ctx, const CoarseEstimate& coarse, const FrameFeatures* features) {
    if (!placeAt(ctx, coarse, features)) return false;
    buildGraph(ctx);
    optimiseGraph(ctx);
    return true;
  }

  /// The current frame as a node at a coarse pose (segmented under it), before the graph.
  bool placeAt(FrameContext& ctx, const CoarseEstimate& coarse, const FrameFeatures* features) {
    if (features) ctx.features = *features;
    ctx.coarse = coarse;
    if (!segmentObject(ctx)) return false;
    ctx.coarse_evidence = ctx.coarse.last_inliers;  // buildGraph may move them into an edge
    makeNode(ctx);
    return true;
  }

  /// The object's mask under the coarse pose; keypoints off it are dropped.
  bool segmentObject(FrameContext& ctx) {
    clock_.enter(&StageTimings::mask);
    ctx.masked.mask = ctx.result.mask = masks_.mask(ctx.frame, observed(), ctx.coarse.T_cam_obj);
    if (cv::countNonZero(ctx.masked.mask) == 0) return false;
    const std::vector<int> kept = keepFeaturesInside(ctx.features, ctx.masked.mask);
    std::vector<FeatureMatch> remapped;
    for (const FeatureMatch& m : ctx.coarse.last_inliers)
      if (const int second = kept[std::size_t(m.second)]; second >= 0) remapped.push_back({m.first, second});
    ctx.coarse.last_inliers = std::move(remapped);
    return true;
  }

  /// A frame as a graph node on the tracker's grid, with an intensity image unless no term of the
  /// energy reads one, and a silhouette image where a term reads one and the masks outline the
  /// object (the mask source's kOutline).
  Keyframe keyframeOf(int id, const RgbdFrame& frame, const cv::Mat& mask, FrameFeatures features, const SE3d& T_cam_obj) const {
    bool with_image = true;
    MaskOutline outline = MaskOutline::none;
    if constexpr (requires { Masks::kOutline; }) outline = Masks::kOutline;
    if constexpr (requires { energy_.readsImages(); }) with_image = energy_.readsImages();
    if constexpr (requires { energy_.readsSilhouettes(); })
      if (!energy_.readsSilhouettes()) outline = MaskOutline::none;
    return makeKeyframe(id, frame, mask, std::move(features), T_cam_obj, camera_, grid_step_, with_image, outline);
  }

  /// The current frame as a graph node at its coarse pose, with its features. Its grid and images
  /// depend on the mask alone: under the mask of the node before (a given mask, tried again from
  /// another coarse pose or with keypoints after the surface alone) they are kept.
  const Keyframe& makeNode(FrameContext& ctx) {
    clock_.enter(&StageTimings::graph);
    if (!ctx.current_mask.empty() && ctx.current_mask.data == ctx.masked.mask.data) {
      ctx.current.features = std::move(ctx.features);
      ctx.current.T_cam_obj = ctx.coarse.T_cam_obj;
      return ctx.current;
    }
    ctx.current_mask = ctx.masked.mask;
    return ctx.current = keyframeOf(ctx.id, ctx.masked, ctx.masked.mask, std::move(ctx.features), ctx.coarse.T_cam_obj);
  }

  /// Paper IV-C, IV-D: the current frame and the keyframes selected for its coarse pose, all pairs.
  /// The edges' correspondences (matching and RANSAC) are charged to the matching stage; the
  /// current frame's edges are matched on OpenCV's threads where both policies allow concurrent
  /// calls (ConcurrentCalls: the CPU ones; a GPU backend's are called from one thread).
  void buildGraph(FrameContext& ctx) {
    constexpr Execution edges = ConcurrentCalls<Correspondences> && ConcurrentCalls<Registration> ? Execution::Parallel
                                                                                                   : Execution::Serial;
    const LastFrameLink last{last_->keypoints.id, ctx.coarse.from_last ? &ctx.coarse.last_inliers : nullptr};
    ctx.graph = clock_.measure(&StageTimings::matching, [&] {
      return buildPoseGraph(pool_, settings_.max_keyframes, ctx.current, ctx.coarse.T_cam_obj, last, cache_,
                            [&](const Keyframe& a, const Keyframe& b, const SE3d& T_a, const SE3d& T_b) {
                              return edgeCorrespondences(a, b, T_a, T_b);
                            },
                            edges);
    });
  }

  /// Feature correspondences of an edge (paper IV-D): matches gated by the current poses (the gate
  /// widened for the sensor's noise), pruned by RANSAC; fewer than min_edge_correspondences count
  /// as none, so a frame with fewer features (one tracked without keypoints) is not matched at all.
  std::vector<FeatureMatch> edgeCorrespondences(const Keyframe& a, const Keyframe& b, const SE3d& T_a, const SE3d& T_b) const {
    const auto fewest = std::size_t(std::max(0, settings_.min_edge_correspondences));
    if (a.features.size() < fewest || b.features.size() < fewest) return {};
    const SurfaceGate gate = settings_.edge_gate.widened(NoiseScale::between(a.features.noise_scale, b.features.noise_scale));
    PairRegistration pair = registerPair(a.features, b.features, MatchGate{(T_b * T_a.inverse()).cast<float>(), gate}, nullptr);
    if (int(pair.inliers.size()) < settings_.min_edge_correspondences) return {};
    return std::move(pair.inliers);
  }

  /// Unlike the original code, the graph runs even when the frame has no feature edge: the dense
  /// term alone often holds the pose, and the verification below catches it when it does not.
  void optimiseGraph(FrameContext& ctx) {
    clock_.enter(&StageTimings::solve);
    if constexpr (requires { energy_.over(ctx.graph, &linearisations_); })
      ctx.optimisation = optimizePoseGraph(energy_.over(ctx.graph, &linearisations_), solver_, ctx.graph.poses, settings_.gauss_newton);
    else
      ctx.optimisation = optimizePoseGraph(energy_.over(ctx.graph), solver_, ctx.graph.poses, settings_.gauss_newton);
  }

  /// The graph refines the coarse pose; it may not throw away the evidence behind it. Where RANSAC
  /// found the coarse pose with the last good frame on recovery_min_inliers or more inliers (more
  /// than chance gathers), the graph's pose must keep min_kept_coarse_inliers of them within the
  /// edge gate. A box turned by 90 degrees can agree with the keyframes' surfaces (the verifier
  /// alone accepted such a pose on a 1,500-frame run of the default motion, after the graph had
  /// diverged from 239 followed keypoints); it cannot keep its own feature pairs.
  bool keepsCoarseEvidence(const FrameContext& ctx) const {
    const std::vector<FeatureMatch>& inliers = ctx.coarse_evidence;
    if (!ctx.coarse.from_last || int(inliers.size()) < settings_.recovery_min_inliers) return true;
    const KeypointFrame& last = last_->keypoints;
    const FrameFeatures& current = ctx.current.features;
    const SurfaceGate gate = settings_.edge_gate.widened(NoiseScale::between(last.features.noise_scale, current.noise_scale));
    const SE3d T_current_last = ctx.graph.poses.back() * last.T_cam_obj.inverse();
    const MatchGate under_graph{T_current_last.cast<float>(), gate};  // GateTest keeps a reference
    const GateTest test(under_graph, last.features, current);
    int kept = 0;
    for (const FeatureMatch& m : inliers) kept += test.admits(test.move(m.first), m.second);
    return kept >= settings_.min_kept_coarse_inliers * double(inliers.size());
  }

  /// The graph's result when the verifier trusts it and it keeps its coarse evidence, else the
  /// coarse pose, unless there is none or the track is being re-acquired.
  bool acceptPose(FrameContext& ctx) { return takeGraphPose(ctx) || takeCoarsePose(ctx); }

  /// The graph's result when the verifier trusts it and it keeps its coarse evidence (the keyframes
  /// take their optimised poses too).
  bool takeGraphPose(FrameContext& ctx) {
    if (!verifier_.accepts(ctx.graph, ctx.coarse.evidence) || !keepsCoarseEvidence(ctx)) return false;
    for (std::size_t n = 0; n < ctx.graph.pool_indices.size(); ++n)
      pool_[ctx.graph.pool_indices[n]].T_cam_obj = ctx.graph.poses[n];
    ctx.result.T_cam_obj = ctx.graph.poses.back();
    ctx.result.status = TrackStatus::Tracked;
    ctx.result.stability = stabilityOf(ctx);
    return true;
  }

  /// The coarse pose RANSAC found, as the frame's (CoarseOnly), where the graph's is not trusted;
  /// none where RANSAC found none or the track is being re-acquired.
  bool takeCoarsePose(FrameContext& ctx) {
    if (!ctx.coarse.found || ctx.recovering) return false;
    ctx.result.T_cam_obj = ctx.coarse.T_cam_obj;
    ctx.result.status = TrackStatus::CoarseOnly;
    ctx.result.stability.reset();
    return true;
  }

  /// poseStability of the frame's node, the graph's last, at the last linearisation; its points'
  /// centroid moved into the object frame under the graph's pose.
  double stabilityOf(const FrameContext& ctx) const {
    const Eigen::MatrixXd& information = ctx.optimisation.information;
    if (information.rows() < 6) return 0.0;
    const SurfaceSpread spread = spreadOf(ctx.current.surface);
    return poseStability(information.bottomRightCorner<6, 6>(), ctx.graph.poses.back().inverse() * spread.centroid,
                         spread.rms_radius);
  }

  /// Followed keypoints carry the descriptors of the frame their chain began on, which a turned
  /// view may no longer match: where the detected keypoints found no pose with the last frame and
  /// the graph from the last pose was refused, following's pose in reserve (trackByFollowing) is
  /// tried -- the graph on the followed keypoints, or, refused again, that pose itself as RANSAC's
  /// between consecutive frames (CoarseOnly). The frame keeps its detected keypoints for later
  /// (a keyframe's, the next frame's to follow).
  bool refineFromFollowing(FrameContext& ctx) {
    if (!ctx.followed_reserve || !ctx.detected_kept) return false;
    FollowedReserve& reserve = *ctx.followed_reserve;
    ctx.result.followed = ctx.result.matches = int(reserve.keypoints.size());  // one match per followed keypoint
    ctx.result.inliers = int(reserve.coarse.last_inliers.size());
    ctx.features = std::move(reserve.keypoints);
    if (!optimiseFrom(ctx, reserve.coarse, nullptr) || !acceptPose(ctx)) return false;
    ctx.current.features = std::move(*ctx.detected_kept);
    keepFeaturesInside(ctx.current.features, ctx.masked.mask);
    return true;
  }

  /// The mask came from the coarse pose; what the tracker keeps of this frame (a keyframe, the
  /// next frame's search region) is cut with the final pose, where the mask depends on it.
  void cutMaskWithFinalPose(FrameContext& ctx) {
    clock_.enter(&StageTimings::mask);
    const cv::Mat refined = masks_.mask(ctx.frame, observed(), ctx.result.T_cam_obj);
    if (refined.data == ctx.masked.mask.data || cv::countNonZero(refined) == 0) return;
    ctx.masked.mask = ctx.result.mask = refined;
    keepFeaturesInside(ctx.current.features, refined);
    ctx.current_mask = refined;
    ctx.current = keyframeOf(ctx.id, ctx.masked, refined, std::move(ctx.current.features), ctx.result.T_cam_obj);
  }

  /// Paper IV-E: the frame joins the pool when it shows a novel view (a copy only then: the graph
  /// is done, and the features move on to the next frame's coarse step). A keyframe carries
  /// keypoints for later edges and re-acquisition: a frame tracked without them detects them now.
  void admitKeyframe(FrameContext& ctx) {
    clock_.enter(&StageTimings::graph);
    ctx.current.T_cam_obj = ctx.result.T_cam_obj;
    if (ctx.result.status == TrackStatus::Tracked &&
        pool_.isNovelView(ctx.result.T_cam_obj.rotation(), radians(settings_.new_keyframe_rotation_deg))) {
      if (!ctx.keypoints_detected) {
        detectKeypoints(ctx);
        ctx.current.features = std::move(ctx.features);
        clock_.enter(&StageTimings::graph);
      }
      if (const int evicted = pool_.add(ctx.current); evicted >= 0) {
        cache_.forget(evicted);
        linearisations_.forget(evicted);
      }
    }
    KeypointFrame keypoints = ctx.keypoints_detected || ctx.keypoints_followed
                                  ? keypointFrame(ctx.id, ctx.result.T_cam_obj, std::move(ctx.current.features), grayOf(ctx),
                                                  ctx.masked.mask, ctx.keypoints_detected ? 0 : ctx.chain_start)
                                  : std::move(last_->keypoints);
    last_ = LastGood{ctx.id, ctx.result.T_cam_obj, ctx.current.surface, std::move(keypoints)};
    lost_streak_ = 0;
  }

  /// A lost frame keeps the last good pose and says so; the next one is matched against that frame.
  TrackResult lost(FrameContext& ctx) {
    ++lost_streak_;
    ctx.result.T_cam_obj = last_->T_cam_obj;
    ctx.result.status = TrackStatus::Lost;
    ctx.result.timings = clock_.stop();
    return std::move(ctx.result);
  }

  PinholeCameraf camera_;
  Settings settings_;
  EnergyT energy_;
  Solver solver_;
  Correspondences correspondences_;
  Masks masks_;
  Registration registration_;
  Verifier verifier_;
  KeyframePool pool_;
  CorrespondenceCache cache_;
  EdgeLinearisationCache linearisations_;  ///< edges between keyframes, relinearised lazily (settings_.relinearisation)
  std::optional<LastGood> last_;
  StageClock clock_;
  int grid_step_ = 1;  ///< of every surface grid of this track (chosen at initialize)
  int frame_index_ = 0;
  int lost_streak_ = 0;  ///< frames lost since the last good one
};

}  // namespace bundletrack
