#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bundletrack/core/error.hpp"
#include "bundletrack/tracking/any_tracker.hpp"

namespace bundletrack {

/// Several rigid objects in one camera. Each object has a tracker of its own (its keyframes, its
/// pose graph, its lost frames) made by `make`; they share the frame: the caller preprocesses it
/// once, over regionOfInterest (the union of the objects' regions, so every tracker finds inside
/// its own region what it would find alone), and track() runs the objects one after another, each
/// tracker with its own parallel loops over the thread pool: side by side, each tracker on one
/// thread, a frame waited for the slower object, and the whole run took 1.16x as long with two
/// objects on two cores, 1.04x with three (bench/multi_object.sh, medians of five alternating
/// runs). An object starts with the first frame that brings it a non-empty mask, so objects
/// can enter at different frames; each result is the one its tracker gives alone on that frame.
class MultiObjectTracker {
 public:
  using MakeTracker = std::function<std::unique_ptr<AnyTracker>()>;

  MultiObjectTracker(std::size_t objects, const MakeTracker& make) : trackers_(objects), started_(objects, false) {
    for (auto& tracker : trackers_) tracker = make();
  }

  std::size_t size() const { return trackers_.size(); }
  bool started(std::size_t k) const { return started_.at(k); }
  const AnyTracker& tracker(std::size_t k) const { return *trackers_.at(k); }

  /// What object k gets of a frame: its mask (empty: none, as for a tracker that propagates its
  /// masks); nothing: it sits the frame out (its data could not be read), which its tracker never
  /// sees.
  using ObjectMasks = std::vector<std::optional<cv::Mat>>;

  /// The part of the next frame to preprocess: the union of the regions the objects' trackers
  /// ask for (regionOfInterest with the object's mask), over the objects that are started or start
  /// with this frame and do not sit it out. Empty when no object is in it.
  cv::Rect regionOfInterest(cv::Size image, const ObjectMasks& masks) const {
    requireOnePer(masks, "regionOfInterest");
    cv::Rect region;
    for (std::size_t k = 0; k < size(); ++k) {
      if (!masks[k] || (!started_[k] && !startsWith(*masks[k]))) continue;
      const cv::Rect own = trackers_[k]->regionOfInterest(image, *masks[k]);
      region = region.area() > 0 ? region | own : own;
    }
    return region;
  }

  /// One frame for every object: a started object is tracked with `frame` and its mask of `masks`;
  /// an object not started starts when its mask is non-empty, at start_poses[k] (T_cam_obj). The
  /// result of object k, or nothing while it has not started or when it sits the frame out.
  std::vector<std::optional<TrackResult>> track(const RgbdFrame& frame, const ObjectMasks& masks,
                                                const std::vector<SE3d>& start_poses) {
    requireOnePer(masks, "track (masks)");
    if (start_poses.size() != size())
      throw InputError("MultiObjectTracker::track", "needs one start pose per object (" + std::to_string(size()) +
                                                        "), got " + std::to_string(start_poses.size()));
    std::vector<std::optional<TrackResult>> results(size());
    for (std::size_t k = 0; k < size(); ++k) {
      if (!masks[k]) continue;
      const bool starts = !started_[k] && startsWith(*masks[k]);
      if (!started_[k] && !starts) continue;
      RgbdFrame own = frame;  // shares the images; the object's own mask
      own.mask = *masks[k];
      results[k] = starts ? trackers_[k]->initialize(own, start_poses[k]) : trackers_[k]->track(own);
    }
    for (std::size_t k = 0; k < size(); ++k) started_[k] = started_[k] || results[k].has_value();
    return results;
  }

 private:
  static bool startsWith(const cv::Mat& mask) { return !mask.empty() && cv::countNonZero(mask) > 0; }

  void requireOnePer(const ObjectMasks& masks, const char* call) const {
    if (masks.size() != size())
      throw InputError(std::string("MultiObjectTracker::") + call,
                       "needs one mask per object (" + std::to_string(size()) + "), got " + std::to_string(masks.size()));
  }

  std::vector<std::unique_ptr<AnyTracker>> trackers_;
  std::vector<bool> started_;
};

}  // namespace bundletrack
