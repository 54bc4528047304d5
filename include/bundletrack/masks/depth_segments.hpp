#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "bundletrack/core/depth_noise.hpp"

namespace bundletrack {

/// One surface of the depth image: pixels joined by depth-continuous 4-neighbour steps.
struct DepthSegment {
  int pixels = 0;
  Eigen::Vector3f low = Eigen::Vector3f::Constant(INFINITY), high = -Eigen::Vector3f::Constant(INFINITY);

  float diagonal() const { return pixels > 0 ? (high - low).norm() : 0.0f; }
};

/// Grows a region from the pixels in `frontier` over 4-neighbours whose depth differs by at most
/// `continuity` (widened by `noise` at the depth of the pixel they are reached from: the depth
/// steps of one slanted surface grow with the sensor's noise and quantisation) from that pixel:
/// claim(q) decides whether neighbour q joins (and marks it), reached(p) sees every pixel of the
/// region once.
template <typename Claim, typename Reached>
void growOverContinuousDepth(const cv::Mat& depth, float continuity, const NoiseScale& noise,
                             std::vector<cv::Point>& frontier, Claim&& claim, Reached&& reached) {
  while (!frontier.empty()) {
    const cv::Point p = frontier.back();
    frontier.pop_back();
    reached(p);
    const float z = depth.at<float>(p), step_limit = noise.widen(continuity, z);
    for (const cv::Point step : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
      const cv::Point q = p + step;
      if (q.x < 0 || q.y < 0 || q.x >= depth.cols || q.y >= depth.rows) continue;
      const float zq = depth.at<float>(q);
      if (zq <= 0.0f || std::abs(zq - z) > step_limit || !claim(q)) continue;
      frontier.push_back(q);
    }
  }
}

/// Splits the valid depth into surfaces that neighbouring pixels join when their depths differ by
/// at most `continuity` widened by `noise` (growOverContinuousDepth). `labels` (CV_32SC1) gets each pixel's segment index, -1 where
/// depth is invalid; returns the segments with their sizes and 3-D bounding boxes.
inline std::vector<DepthSegment> segmentDepth(const cv::Mat& depth, const cv::Mat& points, float continuity,
                                              const NoiseScale& noise, cv::Mat& labels) {
  labels.create(depth.size(), CV_32SC1);
  labels.setTo(-1);
  std::vector<DepthSegment> segments;
  std::vector<cv::Point> frontier;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (depth.at<float>(v, u) <= 0.0f || labels.at<int>(v, u) >= 0) continue;
      const int id = int(segments.size());
      DepthSegment& segment = segments.emplace_back();
      labels.at<int>(v, u) = id;
      frontier.assign(1, {u, v});
      growOverContinuousDepth(
          depth, continuity, noise, frontier,
          [&](const cv::Point& q) {
            if (labels.at<int>(q) >= 0) return false;
            labels.at<int>(q) = id;
            return true;
          },
          [&](const cv::Point& p) {
            const cv::Vec3f& x = points.at<cv::Vec3f>(p);
            ++segment.pixels;
            segment.low = segment.low.cwiseMin(Eigen::Vector3f(x[0], x[1], x[2]));
            segment.high = segment.high.cwiseMax(Eigen::Vector3f(x[0], x[1], x[2]));
          });
    }
  }
  return segments;
}

}  // namespace bundletrack
