#pragma once

#include <optional>
#include <utility>

#include <opencv2/core.hpp>

#include "bundletrack/core/rgbd_frame.hpp"

namespace bundletrack::io {

/// A frame as the reading thread (ReadAhead) hands it over: its files decoded and, where the
/// region the tracker will ask for could be foretold from the frame's own masks (a tracker with
/// given masks asks for maskRegion of its mask, once started), preprocessed over that region
/// too, so that preprocessing overlaps tracking the frame before.
struct FrameAhead {
  RawFrame raw;
  std::optional<RgbdFrame> preprocessed;
};

/// On the reading thread: `raw`, and the frame preprocessed over `foretold` where one is given.
/// `preprocess(RawFrame, cv::Rect)` makes the frame (makeFrame with the sequence's camera and
/// settings); `raw`'s images are shared, not copied.
template <typename Preprocess>
FrameAhead frameAhead(RawFrame raw, const std::optional<cv::Rect>& foretold, Preprocess&& preprocess) {
  FrameAhead ahead{std::move(raw), std::nullopt};
  if (foretold) ahead.preprocessed = preprocess(ahead.raw, *foretold);
  return ahead;
}

/// On the tracking thread: the frame preprocessed over `region` (the tracker's regionOfInterest).
/// The one made ahead where it was made over exactly that region -- the same frame, bit for bit --
/// else made now.
template <typename Preprocess>
RgbdFrame preprocessedOver(FrameAhead ahead, const cv::Rect& region, Preprocess&& preprocess) {
  if (ahead.preprocessed && ahead.preprocessed->region == preprocessedRegion(region, ahead.raw.depth.size()))
    return std::move(*ahead.preprocessed);
  return preprocess(std::move(ahead.raw), region);
}

}  // namespace bundletrack::io
