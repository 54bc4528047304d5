#pragma once

#include <optional>

#include "bundletrack/core/error.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/silhouette_image.hpp"
#include "bundletrack/masks/depth_segments.hpp"
#include "bundletrack/masks/mask_source.hpp"

namespace bundletrack {

struct GivenMaskSettings {
  /// Drop what a mask took in of the background beside the object (withoutBackgroundSeenPast):
  /// a segmentation's outline errs by pixels, and at 3 m a 3 px error is 7 % of a 20 cm box's
  /// width, all of it on surfaces far behind the object.
  bool drop_background = true;
  /// Neighbouring pixels of one surface differ by less than this in depth (as PropagatedMaskSettings).
  float depth_continuity = 0.01f;
};

/// Masks that come with the data (the frame's own mask, e.g. from masks/<name>.png): the same
/// mask whatever the tracker knows, less the background it took in beside the object.
class GivenMasks {
 public:
  using Settings = GivenMaskSettings;

  explicit GivenMasks(Settings settings = {}) : settings_(settings) {}

  /// Each mask is the object's outline as the data sees it, independent of any pose, at every
  /// pixel whether depth was read there or not (a segmentation of the colour image): the
  /// silhouette term may read it (a mask source without kOutline makes no silhouettes).
  static constexpr MaskOutline kOutline = MaskOutline::every_pixel;

  /// The given mask's bounding box; the whole image without one (track() then reports it).
  cv::Rect regionOfInterest(cv::Size image, const cv::Mat& given_mask, const ObservedObject&,
                            const std::optional<SE3d>&) const {
    return maskBoxOrWhole(given_mask, image);
  }

  /// The frame's mask less the background it took in beside the object (withoutBackgroundSeenPast).
  cv::Mat frameMask(const RgbdFrame& frame) const {
    if (frame.mask.empty() || !settings_.drop_background) return frame.mask;
    return withoutBackgroundSeenPast(frame.mask, frame.depth, settings_.depth_continuity, frame.noise);
  }

  cv::Mat start(const RgbdFrame& first, const PinholeCameraf&, const SE3d&, int) {
    if (first.mask.empty() || cv::countNonZero(first.mask) == 0)
      throw InputError("frame " + first.name, "the first frame needs a non-empty object mask");
    return first.mask;
  }

  cv::Mat searchRegion(const RgbdFrame& frame, const ObservedObject&, const std::optional<SE3d>&) const {
    return mask(frame);
  }

  cv::Mat mask(const RgbdFrame& frame, const ObservedObject&, const SE3d&) const { return mask(frame); }

 private:
  static cv::Mat mask(const RgbdFrame& frame) {
    if (frame.mask.empty())
      throw InputError("frame " + frame.name, "no object mask: tracking with given masks needs one for every frame");
    return frame.mask;
  }

  Settings settings_;
};

}  // namespace bundletrack
