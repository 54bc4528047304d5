#pragma once

#include "bundletrack/core/error.hpp"
#include "bundletrack/masks/mask_source.hpp"

namespace bundletrack {

/// Masks that come with the data (the frame's own mask, e.g. from masks/<name>.png).
struct GivenMasks {
  cv::Mat mask(const RgbdFrame& frame) const {
    if (frame.mask.empty())
      throw InputError("frame " + frame.name, "no object mask: tracking with given masks needs one for every frame");
    return frame.mask;
  }
};

}  // namespace bundletrack
