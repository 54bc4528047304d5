#pragma once

#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/features/correspondence_source.hpp"
#include "bundletrack/features/matching.hpp"

namespace bundletrack::cuda {

/// Exhaustive two-nearest-neighbour search on the GPU: for every row of `query`, the nearest and
/// second-nearest rows of `train` (CV_32F rows under NORM_L2, CV_8U rows under NORM_HAMMING), as
/// cv::BFMatcher::knnMatch(k = 2) finds them. Device buffers persist across calls and only grow.
class DescriptorMatcher {
 public:
  DescriptorMatcher();
  std::vector<TwoNearest> twoNearest(const cv::Mat& query, const cv::Mat& train, int norm_type) const;

 private:
  struct Workspace;
  std::shared_ptr<Workspace> workspace_;
};

/// A CorrespondenceSource whose matching runs on the GPU: the Detector's keypoints (detected on
/// the CPU), matched exhaustively in both directions with the ratio test, mutual check and gate of
/// bundletrack::matchFeatures with MatchSettings::guided off, so it returns the same matches.
template <CorrespondenceSource Detector>
class GpuMatched {
 public:
  explicit GpuMatched(Detector detector = Detector(), MatchSettings matching = MatchSettings())
      : detector_(std::move(detector)), matching_(matching) {}

  FrameFeatures detect(const RgbdFrame& frame) { return detector_.detect(frame); }

  /// The Detector's following by optical flow, where it has one (FollowingSource).
  FollowedFeatures follow(const cv::Mat& last_gray, const cv::Mat& last_mask, const FrameFeatures& last,
                          const RgbdFrame& frame, const cv::Mat& gray) const
    requires FollowingSource<Detector>
  {
    return detector_.follow(last_gray, last_mask, last, frame, gray);
  }

  std::vector<FeatureMatch> match(const FrameFeatures& first, const FrameFeatures& second,
                                  const std::optional<MatchGate>& gate = std::nullopt) const {
    if (first.size() < 2 || second.size() < 2) return {};  // no second neighbour for the ratio test
    return mutualMatches(matcher_.twoNearest(first.descriptors, second.descriptors, first.norm_type),
                         matcher_.twoNearest(second.descriptors, first.descriptors, first.norm_type), first, second,
                         matching_.ratio, gate);
  }

 private:
  Detector detector_;
  MatchSettings matching_;
  DescriptorMatcher matcher_;
};

}  // namespace bundletrack::cuda
