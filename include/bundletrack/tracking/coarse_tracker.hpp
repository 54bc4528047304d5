#pragma once

#include <optional>

#include "bundletrack/core/error.hpp"
#include "bundletrack/features/correspondence_source.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/registration/ransac.hpp"
#include "bundletrack/tracking/stopwatch.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bundletrack {

struct CoarseTrackerSettings {
  RansacSettings ransac;
  /// Fewest RANSAC inliers that count as a pose: the 3 sampled matches and 2 more that agree
  /// within 5 mm and 45 degrees. Small, weakly textured objects give only 5-10 correct matches per
  /// frame (the shared mug: median 7), so a higher bar loses them; a wrong pose that passes it is
  /// caught by the pose graph's residuals, not here.
  int min_inliers = 5;
};


/// Frame-to-frame tracking by feature RANSAC alone (paper IV-B): T_cam_obj(t) = Delta(t) *
/// T_cam_obj(t-1), with Delta(t) mapping the previous frame's points onto the current ones. The
/// baseline the pose graph must beat. A frame with fewer than min_inliers inliers is reported
/// Lost with the last good pose, and the next frame is matched against the last good frame.
template <CorrespondenceSource Correspondences = SiftFeatures>
class CoarseTracker {
 public:
  using Settings = CoarseTrackerSettings;

  explicit CoarseTracker(Correspondences correspondences = Correspondences(), Settings settings = Settings())
      : correspondences_(std::move(correspondences)), settings_(settings), ransac_(settings.ransac) {}

  /// Starts a track at frame 0 with its known pose (identity makes the first camera the object frame).
  TrackResult initialize(const RgbdFrame& frame, const SE3d& T_cam_obj = {}) {
    if (frame.mask.empty() || cv::countNonZero(frame.mask) == 0)
      throw InputError("frame " + frame.name, "the first frame needs a non-empty object mask");
    Stopwatch watch;
    reference_ = correspondences_.detect(frame);
    T_cam_obj_ = T_cam_obj;
    TrackResult result{T_cam_obj, TrackStatus::Tracked, int(reference_->size()), 0, 0, frame.mask, {}};
    result.timings.features = result.timings.total = watch.lap();
    return result;
  }

  TrackResult track(const RgbdFrame& frame) {
    if (!reference_) throw InputError("frame " + frame.name, "track() called before initialize()");
    TrackResult result;
    result.mask = frame.mask;
    Stopwatch watch, total;
    FrameFeatures features = correspondences_.detect(frame);
    result.timings.features = watch.lap();
    const auto matches = correspondences_.match(*reference_, features, std::nullopt);
    result.timings.matching = watch.lap();
    const RansacResult ransac = ransac_.estimate(*reference_, features, matches);
    result.timings.ransac = watch.lap();
    result.keypoints = int(features.size());
    result.matches = int(matches.size());
    result.inliers = int(ransac.inliers.size());
    if (result.inliers >= settings_.min_inliers) {
      T_cam_obj_ = ransac.T_second_first * T_cam_obj_;
      reference_ = std::move(features);
      result.status = TrackStatus::CoarseOnly;
    } else {
      result.status = TrackStatus::Lost;
    }
    result.T_cam_obj = T_cam_obj_;
    result.timings.total = total.lap();
    return result;
  }

 private:
  Correspondences correspondences_;
  Settings settings_;
  Ransac ransac_;
  std::optional<FrameFeatures> reference_;
  SE3d T_cam_obj_;
};

}  // namespace bundletrack
