#pragma once

#include <cstddef>
#include <memory>
#include <utility>

#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/graph/object_model.hpp"
#include "bundletrack/tracking/track_result.hpp"

namespace bundletrack {

/// Any tracker behind one small interface, for code that chooses its tracker at run time (the
/// command-line tracker, the benchmarks, bindings). Feed frames in order: initialize() with the
/// first, then track() each one.
class AnyTracker {
 public:
  virtual ~AnyTracker() = default;
  virtual TrackResult initialize(const RgbdFrame& frame, const SE3d& T_cam_obj) = 0;
  virtual TrackResult track(const RgbdFrame& frame) = 0;
  /// The part of the next frame's image to preprocess (Tracker::regionOfInterest); the whole
  /// image for a tracker that does not say.
  virtual cv::Rect regionOfInterest(cv::Size image, const cv::Mat& given_mask) const = 0;
  /// Keyframes in memory (0 for a tracker without a pool).
  virtual std::size_t keyframeCount() const = 0;
  /// The object's model fused from the keyframes (fuseObjectModel); empty without a pool.
  virtual std::vector<ModelPoint> objectModel() const = 0;
};

namespace detail {

template <typename TrackerT>
class ErasedTracker final : public AnyTracker {
 public:
  explicit ErasedTracker(TrackerT tracker) : tracker_(std::move(tracker)) {}
  TrackResult initialize(const RgbdFrame& frame, const SE3d& T_cam_obj) override {
    return tracker_.initialize(frame, T_cam_obj);
  }
  TrackResult track(const RgbdFrame& frame) override { return tracker_.track(frame); }
  cv::Rect regionOfInterest(cv::Size image, const cv::Mat& given_mask) const override {
    if constexpr (requires { tracker_.regionOfInterest(image, given_mask); })
      return tracker_.regionOfInterest(image, given_mask);
    else
      return cv::Rect({0, 0}, image);
  }
  std::size_t keyframeCount() const override {
    if constexpr (requires { tracker_.keyframes().size(); }) return tracker_.keyframes().size();
    else return 0;
  }
  std::vector<ModelPoint> objectModel() const override {
    if constexpr (requires { fuseObjectModel(tracker_.keyframes()); }) return fuseObjectModel(tracker_.keyframes());
    else return {};
  }

 private:
  TrackerT tracker_;
};

}  // namespace detail

/// Wraps a tracker composed at compile time (Tracker<...>, CoarseTracker<...>, your own).
template <typename TrackerT>
std::unique_ptr<AnyTracker> eraseTracker(TrackerT tracker) {
  return std::make_unique<detail::ErasedTracker<TrackerT>>(std::move(tracker));
}

}  // namespace bundletrack
