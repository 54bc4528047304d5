#pragma once

#include <optional>

#include "bundletrack/core/error.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/silhouette_image.hpp"
#include "bundletrack/masks/mask_source.hpp"

namespace bundletrack {

/// Masks that come with the data (the frame's own mask, e.g. from masks/<name>.png): the same
/// mask whatever the tracker knows.
struct GivenMasks {
  /// Each mask is the object's outline as the data sees it, independent of any pose, at every
  /// pixel whether depth was read there or not (a segmentation of the colour image): the
  /// silhouette term may read it (a mask source without kOutline makes no silhouettes).
  static constexpr MaskOutline kOutline = MaskOutline::every_pixel;

  /// The given mask's bounding box; the whole image without one (track() then reports it).
  cv::Rect regionOfInterest(cv::Size image, const cv::Mat& given_mask, const ObservedObject&,
                            const std::optional<SE3d>&) const {
    return maskBoxOrWhole(given_mask, image);
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
};

}  // namespace bundletrack
