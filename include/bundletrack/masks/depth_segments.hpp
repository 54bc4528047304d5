#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/depth_noise.hpp"

namespace bundletrack {

/// One surface of the depth image: pixels joined by depth-continuous 4-neighbour steps.
struct DepthSegment {
  int pixels = 0;
  Eigen::Vector3f low = Eigen::Vector3f::Constant(INFINITY), high = -Eigen::Vector3f::Constant(INFINITY);

  float diagonal() const { return pixels > 0 ? (high - low).norm() : 0.0f; }
};

/// A pixel's 4-neighbours, as steps.
inline const std::array<cv::Point, 4> kFourNeighbourSteps{cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)};

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
    for (const cv::Point step : kFourNeighbourSteps) {
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

/// A segmentation's mask without the background it took in beside the object: a mask that
/// reaches past the object's outline (grown, shifted) covers surfaces seen past it. The mask's
/// pixels with depth are split into depth-continuous surfaces (growOverContinuousDepth, steps of at
/// most `continuity` widened by `noise`); a surface that reaches the mask's outline (directly, or
/// across mask pixels without a reading that do: the depth filter clears pixels along depth edges)
/// and lies wholly behind the largest one -- its nearest reading farther than the largest's
/// farthest by more than `continuity` widened there -- is dropped. What stays: the largest surface
/// whatever its depth, everything in front of or within its depth (a handle before a mug's body,
/// the hand holding the object, the table it stands on), surfaces the mask encloses (a mug's inside
/// seen past its rim), pixels without a reading. Returns `mask` itself when nothing is dropped.
inline cv::Mat withoutBackgroundSeenPast(const cv::Mat& mask, const cv::Mat& depth, float continuity,
                                         const NoiseScale& noise) {
  CV_Assert(mask.type() == CV_8UC1 && depth.type() == CV_32FC1 && mask.size() == depth.size());
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return mask;
  const auto inside = [&](const cv::Point& q) {
    return q.x >= 0 && q.y >= 0 && q.x < mask.cols && q.y < mask.rows && mask.at<uchar>(q) != 0;
  };
  const auto unread = [&](const cv::Point& q) { return inside(q) && depth.at<float>(q) <= 0.0f; };
  // The mask's pixels without a reading that the outline reaches, flooded from those beside it.
  cv::Mat outer(box.size(), CV_8UC1, cv::Scalar(0));
  const auto is_outer = [&](const cv::Point& q) { return outer.at<uchar>(q - box.tl()) != 0; };
  std::vector<cv::Point> frontier;
  const auto beside_outline = [&](const cv::Point& p) {
    return std::any_of(kFourNeighbourSteps.begin(), kFourNeighbourSteps.end(), [&](cv::Point step) { return !inside(p + step); });
  };
  for (int v = box.y; v < box.br().y; ++v)
    for (int u = box.x; u < box.br().x; ++u)
      if (unread({u, v}) && beside_outline({u, v})) outer.at<uchar>(v - box.y, u - box.x) = 1, frontier.emplace_back(u, v);
  while (!frontier.empty()) {
    const cv::Point p = frontier.back();
    frontier.pop_back();
    for (const cv::Point step : kFourNeighbourSteps)
      if (const cv::Point q = p + step; unread(q) && !is_outer(q)) outer.at<uchar>(q - box.tl()) = 1, frontier.push_back(q);
  }
  const auto reaches_outline = [&](const cv::Point& p) {
    return std::any_of(kFourNeighbourSteps.begin(), kFourNeighbourSteps.end(), [&](cv::Point step) {
      const cv::Point q = p + step;
      return !inside(q) || (unread(q) && is_outer(q));
    });
  };
  struct Surface {
    int pixels = 0;
    float nearest = INFINITY, farthest = 0.0f;
    bool reaches_outline = false;
  };
  std::vector<Surface> surfaces;
  cv::Mat labels(box.size(), CV_32SC1, cv::Scalar(-1));  // surface of each pixel of the box, -1: none
  const auto label = [&](const cv::Point& p) -> int& { return labels.at<int>(p - box.tl()); };
  for (int v = box.y; v < box.br().y; ++v) {
    for (int u = box.x; u < box.br().x; ++u) {
      if (!inside({u, v}) || depth.at<float>(v, u) <= 0.0f || label({u, v}) >= 0) continue;
      const int id = int(surfaces.size());
      Surface& surface = surfaces.emplace_back();
      label({u, v}) = id;
      frontier.assign(1, {u, v});
      growOverContinuousDepth(
          depth, continuity, noise, frontier,
          [&](const cv::Point& q) {
            if (!inside(q) || label(q) >= 0) return false;
            label(q) = id;
            return true;
          },
          [&](const cv::Point& p) {
            const float z = depth.at<float>(p);
            ++surface.pixels;
            surface.nearest = std::min(surface.nearest, z);
            surface.farthest = std::max(surface.farthest, z);
            surface.reaches_outline = surface.reaches_outline || reaches_outline(p);
          });
    }
  }
  if (surfaces.size() < 2) return mask;
  const Surface& largest = *std::max_element(surfaces.begin(), surfaces.end(),
                                             [](const Surface& a, const Surface& b) { return a.pixels < b.pixels; });
  const float behind = largest.farthest + noise.widen(continuity, largest.farthest);
  std::vector<bool> dropped(surfaces.size());
  for (std::size_t s = 0; s < surfaces.size(); ++s) dropped[s] = surfaces[s].reaches_outline && surfaces[s].nearest > behind;
  if (std::none_of(dropped.begin(), dropped.end(), [](bool d) { return d; })) return mask;
  cv::Mat kept = mask.clone();
  for (int v = 0; v < box.height; ++v)
    for (int u = 0; u < box.width; ++u)
      if (const int id = labels.at<int>(v, u); id >= 0 && dropped[std::size_t(id)]) kept.at<uchar>(box.y + v, box.x + u) = 0;
  return kept;
}

}  // namespace bundletrack
