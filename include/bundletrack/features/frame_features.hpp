#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"

namespace bundletrack {

/// Keypoints of one frame lifted to 3-D: pixel (full resolution), camera-frame point and unit
/// normal (facing the camera), one descriptor row each.
struct FrameFeatures {
  std::vector<cv::Point2f> pixels;
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
  cv::Mat descriptors;  ///< one row per keypoint
  int norm_type = cv::NORM_L2;  ///< distance between descriptors: NORM_L2 (SIFT) or NORM_HAMMING (ORB, AKAZE)
  /// The sensor's NoiseScale at the points' median depth: what distance tolerances between these
  /// points and another frame's are widened by (NoiseScale::between).
  double noise_scale = 1.0;

  std::size_t size() const { return points.size(); }
};

/// Keeps the features whose pixel lies on the mask (CV_8UC1, nonzero); returns, for every old
/// index, the new one (-1: dropped).
inline std::vector<int> keepFeaturesInside(FrameFeatures& features, const cv::Mat& mask) {
  std::vector<int> kept(features.size(), -1);
  int count = 0;
  for (std::size_t k = 0; k < features.size(); ++k) {
    const int u = roundToPixel(features.pixels[k].x), v = roundToPixel(features.pixels[k].y);
    if (u < 0 || v < 0 || u >= mask.cols || v >= mask.rows || !mask.at<uchar>(v, u)) continue;
    features.pixels[std::size_t(count)] = features.pixels[k];
    features.points[std::size_t(count)] = features.points[k];
    features.normals[std::size_t(count)] = features.normals[k];
    if (count != int(k)) features.descriptors.row(int(k)).copyTo(features.descriptors.row(count));
    kept[k] = count++;
  }
  features.pixels.resize(std::size_t(count));
  features.points.resize(std::size_t(count));
  features.normals.resize(std::size_t(count));
  if (!features.descriptors.empty()) features.descriptors = features.descriptors.rowRange(0, count);
  return kept;
}

/// A feature correspondence: index into the first and into the second frame's features.
struct FeatureMatch {
  int first = 0, second = 0;
  bool operator==(const FeatureMatch&) const = default;
};

/// The keypoints of one frame found again in the next (by optical flow): the next frame's features,
/// each keeping the descriptor of the keypoint it follows, and which keypoint of the first each is.
struct FollowedFeatures {
  FrameFeatures features;
  std::vector<FeatureMatch> matches;  ///< first: index in the followed frame's features, second: in `features`
  int tried = 0;  ///< keypoints of the first frame that could be followed (their window on the object)
};

}  // namespace bundletrack
