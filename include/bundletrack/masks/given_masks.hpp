#pragma once

#include <concepts>

#include "bundletrack/core/error.hpp"
#include "bundletrack/core/rgbd_frame.hpp"

namespace bundletrack {

/// Where each frame's object mask comes from. `mask(frame)` returns CV_8UC1, 255 on the object;
/// an all-zero mask means the object is not visible in this frame.
template <typename T>
concept MaskSource = requires(T& source, const RgbdFrame& frame) {
  { source.mask(frame) } -> std::same_as<cv::Mat>;
};

/// Masks that come with the data (the frame's own mask, e.g. from masks/<name>.png).
struct GivenMasks {
  cv::Mat mask(const RgbdFrame& frame) const {
    if (frame.mask.empty())
      throw InputError("frame " + frame.name, "no object mask: tracking with given masks needs one for every frame");
    return frame.mask;
  }
};

}  // namespace bundletrack
