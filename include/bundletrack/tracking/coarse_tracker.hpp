#pragma once

#include <optional>

#include "bundletrack/core/error.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/start_frame_check.hpp"
#include "bundletrack/features/correspondence_source.hpp"
#include "bundletrack/registration/feature_registration.hpp"
#include "bundletrack/tracking/stage_clock.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bundletrack {

struct CoarseTrackerSettings {
  int min_inliers = 5;  ///< as TrackerSettings::min_inliers
};

/// Frame-to-frame tracking by feature registration alone (paper IV-B): T_cam_obj(t) = Delta(t) *
/// T_cam_obj(t-1), with Delta(t) mapping the previous frame's points onto the current ones. The
/// baseline the pose graph must beat. A frame with fewer than min_inliers inliers is reported
/// Lost with the last good pose, and the next frame is matched against the last good frame.
template <CorrespondenceSource Correspondences, FeatureRegistration Registration>
class CoarseTracker {
 public:
  using Settings = CoarseTrackerSettings;

  explicit CoarseTracker(Correspondences correspondences = Correspondences(), Registration registration = Registration(),
                         Settings settings = Settings())
      : correspondences_(std::move(correspondences)), registration_(std::move(registration)), settings_(settings) {}

  /// Starts a track at frame 0 with its known pose (identity makes the first camera the object
  /// frame). A frame without depth under its mask, or a pose it contradicts, is refused
  /// (checkStartFrame).
  TrackResult initialize(const RgbdFrame& frame, const SE3d& T_cam_obj = {}) {
    if (frame.mask.empty() || cv::countNonZero(frame.mask) == 0)
      throw InputError("frame " + frame.name, "the first frame needs a non-empty object mask");
    checkStartFrame(frame, T_cam_obj);
    clock_.start(&StageTimings::features);
    reference_ = correspondences_.detect(frame);
    T_cam_obj_ = T_cam_obj;
    TrackResult result{T_cam_obj, TrackStatus::Tracked, int(reference_->size()), 0, 0, frame.mask, {}};
    result.timings = clock_.stop();
    return result;
  }

  /// The part of the next frame to preprocess: the box of its mask, grown by kRegionMargin.
  cv::Rect regionOfInterest(cv::Size image, const cv::Mat& given_mask) const { return maskRegion(given_mask, image); }

  TrackResult track(const RgbdFrame& frame) {
    if (!reference_) throw InputError("frame " + frame.name, "track() called before initialize()");
    clock_.start(&StageTimings::features);
    TrackResult result;
    result.mask = frame.mask;
    FrameFeatures features = correspondences_.detect(frame);
    const auto matches = clock_.measure(&StageTimings::matching, [&] { return correspondences_.match(*reference_, features, std::nullopt); });
    const auto registration = clock_.measure(&StageTimings::ransac, [&] { return registration_.estimate(*reference_, features, matches); });
    result.keypoints = int(features.size());
    result.matches = int(matches.size());
    result.inliers = int(registration.inliers.size());
    if (result.inliers >= settings_.min_inliers) {
      T_cam_obj_ = registration.T_second_first * T_cam_obj_;
      reference_ = std::move(features);
      result.status = TrackStatus::CoarseOnly;
    } else {
      result.status = TrackStatus::Lost;
    }
    result.T_cam_obj = T_cam_obj_;
    result.timings = clock_.stop();
    return result;
  }

 private:
  Correspondences correspondences_;
  Registration registration_;
  Settings settings_;
  StageClock clock_;
  std::optional<FrameFeatures> reference_;
  SE3d T_cam_obj_;
};

}  // namespace bundletrack
