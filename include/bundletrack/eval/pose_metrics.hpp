#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/eval/kd_tree.hpp"

namespace bundletrack {

/// ADD: mean distance between the model points moved by the true and by the estimated pose.
inline double averageDistance(const std::vector<Eigen::Vector3f>& model, const SE3d& T_true, const SE3d& T_est) {
  const SE3f a = T_true.cast<float>(), b = T_est.cast<float>();
  double sum = 0.0;
  for (const auto& x : model) sum += (a * x - b * x).norm();
  return sum / double(model.size());
}

/// ADD-S: mean over model points moved by the true pose of the distance to the nearest model
/// point moved by the estimated pose (for symmetric objects). `model_tree` holds the model.
inline double averageDistanceSymmetric(const std::vector<Eigen::Vector3f>& model, const KdTree3& model_tree,
                                       const SE3d& T_true, const SE3d& T_est) {
  // min_y ||A x - B y|| = min_y ||B^-1 A x - y||: query the model tree with B^-1 A x.
  const SE3f moved = (T_est.inverse() * T_true).cast<float>();
  double sum = 0.0;
  for (const auto& x : model) sum += std::sqrt(model_tree.nearestSquaredDistance(moved * x));
  return sum / double(model.size());
}

inline double rotationErrorDeg(const SE3d& T_true, const SE3d& T_est) {
  return degrees(rotationGeodesic(T_true.rotation(), T_est.rotation()));
}

inline double translationError(const SE3d& T_true, const SE3d& T_est) {
  return (T_true.translation() - T_est.translation()).norm();
}

/// Area under the accuracy-threshold curve on [0, max_threshold], x100, as the YCB-Video toolbox's
/// VOCap computes it: errors sorted, accuracy at the k-th smallest = k / n, errors above the
/// threshold never count, the precision envelope made monotone, rectangles summed.
inline double areaUnderCurve(std::vector<double> errors, double max_threshold = 0.1) {
  const std::size_t n = errors.size();
  if (n == 0) return 0.0;
  std::sort(errors.begin(), errors.end());
  std::vector<double> recall{0.0}, precision{0.0};
  for (std::size_t k = 0; k < n && errors[k] <= max_threshold; ++k) {
    recall.push_back(errors[k]);
    precision.push_back(double(k + 1) / double(n));
  }
  recall.push_back(max_threshold);
  precision.push_back(precision.back());
  for (std::size_t i = 1; i < precision.size(); ++i) precision[i] = std::max(precision[i], precision[i - 1]);
  double area = 0.0;
  for (std::size_t i = 1; i < recall.size(); ++i)
    if (recall[i] != recall[i - 1]) area += (recall[i] - recall[i - 1]) * precision[i];
  return 100.0 * area / max_threshold;
}

}  // namespace bundletrack
