#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace bundletrack {

/// Keypoints of one frame lifted to 3-D: pixel (full resolution), camera-frame point and unit
/// normal (facing the camera), one descriptor row each.
struct FrameFeatures {
  std::vector<cv::Point2f> pixels;
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
  cv::Mat descriptors;  ///< one row per keypoint
  int norm_type = cv::NORM_L2;  ///< distance between descriptors: NORM_L2 (SIFT) or NORM_HAMMING (ORB, AKAZE)

  std::size_t size() const { return points.size(); }
};

/// A feature correspondence: index into the first and into the second frame's features.
struct FeatureMatch {
  int first = 0, second = 0;
  bool operator==(const FeatureMatch&) const = default;
};

}  // namespace bundletrack
