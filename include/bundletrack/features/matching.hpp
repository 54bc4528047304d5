#pragma once

#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/features2d.hpp>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/features/frame_features.hpp"
#include "bundletrack/features/two_nearest.hpp"

namespace bundletrack {

struct MatchSettings {
  float ratio = 0.8f;  ///< Lowe's ratio test: best distance < ratio * second best, in both directions
  /// With a gate (a known relative pose), compare only the pairs the gate admits and run the ratio
  /// test among them (guided matching): a few candidates per keypoint instead of all of them. It
  /// finds every match the gated exhaustive search finds, and more where a look-alike lies
  /// outside the gate.
  bool guided = true;
};

/// Geometric gate for a pair whose relative pose is already known (docs/DESIGN.md section 3): a
/// match survives when the first point, moved by T_second_first, and the second pass `surface`.
struct MatchGate {
  SE3f T_second_first;
  SurfaceGate surface;
};

/// Distance between descriptor rows a and b (CV_32F rows under NORM_L2, CV_8U rows under NORM_HAMMING).
inline float descriptorDistance(const cv::Mat& a, const cv::Mat& b, int norm_type) {
  if (norm_type == cv::NORM_L2) {
    const float* x = a.ptr<float>();
    const float* y = b.ptr<float>();
    float sum = 0.0f;
    for (int k = 0; k < a.cols; ++k) sum += (x[k] - y[k]) * (x[k] - y[k]);
    return std::sqrt(sum);
  }
  return float(cv::norm(a, b, norm_type));
}

/// A MatchGate ready to test pairs: first's keypoint moved into the second frame once, then
/// compared with any of second's.
class GateTest {
 public:
  GateTest(const MatchGate& gate, const FrameFeatures& first, const FrameFeatures& second)
      : gate_(gate), first_(first), second_(second), bounds_(gate.surface.bounds<float>()) {}

  struct Moved {
    Eigen::Vector3f point, normal;
  };
  Moved move(int i) const {
    return {gate_.T_second_first * first_.points[std::size_t(i)],
            gate_.T_second_first.rotation() * first_.normals[std::size_t(i)]};
  }
  bool admits(const Moved& moved, int j) const {
    return bounds_.admits((moved.point - second_.points[std::size_t(j)]).squaredNorm(),
                          moved.normal.dot(second_.normals[std::size_t(j)]));
  }

 private:
  const MatchGate& gate_;
  const FrameFeatures& first_;
  const FrameFeatures& second_;
  SurfaceGate::Bounds<float> bounds_;
};

/// Pairs that are each other's distinct nearest neighbour (forward[i]: first's keypoint i among
/// second's, backward[j]: the other way), and that the gate admits when there is one. Sorted by
/// the first index. Every matcher (CPU, GPU, guided) ends here.
inline std::vector<FeatureMatch> mutualMatches(const std::vector<TwoNearest>& forward,
                                               const std::vector<TwoNearest>& backward, const FrameFeatures& first,
                                               const FrameFeatures& second, float ratio,
                                               const std::optional<MatchGate>& gate) {
  std::vector<FeatureMatch> matches;
  const auto select = [&](const auto& admits) {
    for (int i = 0; i < int(forward.size()); ++i) {
      const TwoNearest& f = forward[std::size_t(i)];
      if (!f.distinct(ratio)) continue;
      const TwoNearest& b = backward[std::size_t(f.index)];
      if (b.index != i || !b.distinct(ratio) || !admits(i, f.index)) continue;
      matches.push_back({i, f.index});
    }
  };
  if (gate) {
    const GateTest test(*gate, first, second);
    select([&](int i, int j) { return test.admits(test.move(i), j); });
  } else {
    select([](int, int) { return true; });
  }
  return matches;
}

/// Guided matching under a known relative pose: mutual nearest neighbours with the ratio test in
/// both directions, among the pairs the gate admits only. Sorted by the first index.
inline std::vector<FeatureMatch> matchGuided(const FrameFeatures& first, const FrameFeatures& second,
                                             const MatchSettings& settings, const MatchGate& gate) {
  const int n1 = int(first.size()), n2 = int(second.size());
  std::vector<TwoNearest> forward(static_cast<std::size_t>(n1)), backward(static_cast<std::size_t>(n2));
  const GateTest test(gate, first, second);
  for (int i = 0; i < n1; ++i) {
    const GateTest::Moved moved = test.move(i);
    for (int j = 0; j < n2; ++j) {
      if (!test.admits(moved, j)) continue;
      const float distance = descriptorDistance(first.descriptors.row(i), second.descriptors.row(j), first.norm_type);
      forward[std::size_t(i)].offer(distance, j);
      backward[std::size_t(j)].offer(distance, i);
    }
  }
  return mutualMatches(forward, backward, first, second, settings.ratio, std::nullopt);
}

/// Mutual nearest neighbours in descriptor space with the ratio test applied in both directions,
/// so match(a, b) is match(b, a) with the roles swapped (the original code took the union of the
/// two directions instead), then the gate when there is one; with a gate and settings.guided,
/// matchGuided instead. Sorted by the first index.
inline std::vector<FeatureMatch> matchFeatures(const FrameFeatures& first, const FrameFeatures& second,
                                               const MatchSettings& settings,
                                               const std::optional<MatchGate>& gate = std::nullopt) {
  if (gate && settings.guided) return matchGuided(first, second, settings, *gate);
  if (first.size() < 2 || second.size() < 2) return {};  // no second neighbour for the ratio test
  const cv::BFMatcher matcher(first.norm_type);
  const auto twoNearest = [&](const cv::Mat& query, const cv::Mat& train) {
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(query, train, knn, 2);
    std::vector<TwoNearest> nearest(knn.size());
    for (std::size_t k = 0; k < knn.size(); ++k)
      if (knn[k].size() == 2) nearest[k] = {knn[k][0].trainIdx, knn[k][0].distance, knn[k][1].distance};
    return nearest;
  };
  return mutualMatches(twoNearest(first.descriptors, second.descriptors),
                       twoNearest(second.descriptors, first.descriptors), first, second, settings.ratio, gate);
}

}  // namespace bundletrack
