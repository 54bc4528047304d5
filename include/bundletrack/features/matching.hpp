#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core/hal/hal.hpp>
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

/// Distance between row i of descriptors a and row j of b (CV_32F rows under NORM_L2, CV_8U rows
/// under NORM_HAMMING): the kernels of cv::BFMatcher, so guided and exhaustive matching compare
/// the same numbers.
inline float descriptorDistance(const cv::Mat& a, int i, const cv::Mat& b, int j, int norm_type) {
  if (norm_type == cv::NORM_L2) return std::sqrt(cv::hal::normL2Sqr_(a.ptr<float>(i), b.ptr<float>(j), a.cols));
  return float(cv::hal::normHamming(a.ptr<uchar>(i), b.ptr<uchar>(j), a.cols));
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
  /// Farther than this apart along any axis, two points are never admitted (a hair wider than the
  /// gate's distance, against rounding).
  float reach() const { return std::sqrt(bounds_.max_squared_distance) * (1.0f + 1e-5f); }

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
/// both directions, among the pairs the gate admits only. Sorted by the first index. Second's
/// keypoints are sorted once into rows of the gate's reach in y, by x within a row, so each of
/// first's keypoints is tested only against those of its row and the two beside it that lie
/// within reach in x (TwoNearest does not depend on the order of its candidates).
inline std::vector<FeatureMatch> matchGuided(const FrameFeatures& first, const FrameFeatures& second,
                                             const MatchSettings& settings, const MatchGate& gate) {
  const int n1 = int(first.size()), n2 = int(second.size());
  std::vector<TwoNearest> forward(static_cast<std::size_t>(n1)), backward(static_cast<std::size_t>(n2));
  const GateTest test(gate, first, second);
  const float reach = test.reach();
  // Rows in double: two points within reach in y lie in the same or neighbouring rows only if the
  // division does not round them apart (reach keeps a 1e-5 margin; float would round by more
  // than that at y / reach ~ 1e3).
  const auto rowOf = [&](float y) { return std::int64_t(std::floor(double(y) / double(reach))); };
  struct Candidate {
    std::int64_t row;
    float x;
    int index;
    bool operator<(const Candidate& other) const { return row != other.row ? row < other.row : x < other.x; }
  };
  std::vector<Candidate> candidates;
  candidates.reserve(static_cast<std::size_t>(n2));
  for (int j = 0; j < n2; ++j) {
    const Eigen::Vector3f& p = second.points[std::size_t(j)];
    candidates.push_back({rowOf(p.y()), p.x(), j});
  }
  std::sort(candidates.begin(), candidates.end());
  for (int i = 0; i < n1; ++i) {
    const GateTest::Moved moved = test.move(i);
    const std::int64_t row = rowOf(moved.point.y());
    for (std::int64_t r = row - 1; r <= row + 1; ++r) {
      for (auto k = std::lower_bound(candidates.begin(), candidates.end(), Candidate{r, moved.point.x() - reach, 0});
           k != candidates.end() && k->row == r && k->x <= moved.point.x() + reach; ++k) {
        if (!test.admits(moved, k->index)) continue;
        const float distance = descriptorDistance(first.descriptors, i, second.descriptors, k->index, first.norm_type);
        forward[std::size_t(i)].offer(distance, k->index);
        backward[std::size_t(k->index)].offer(distance, i);
      }
    }
  }
  return mutualMatches(forward, backward, first, second, settings.ratio, std::nullopt);
}

/// Mutual nearest neighbours in descriptor space with the ratio test applied in both directions,
/// so match(a, b) is match(b, a) with the roles swapped (the original code took the union of the
/// two directions instead), then the gate when there is one; with a gate and settings.guided,
/// matchGuided instead. One distance matrix serves both directions (cv::batchDistance, the
/// kernel of cv::BFMatcher). Sorted by the first index.
inline std::vector<FeatureMatch> matchFeatures(const FrameFeatures& first, const FrameFeatures& second,
                                               const MatchSettings& settings,
                                               const std::optional<MatchGate>& gate = std::nullopt) {
  if (gate && settings.guided) return matchGuided(first, second, settings, *gate);
  if (first.size() < 2 || second.size() < 2) return {};  // no second neighbour for the ratio test
  cv::Mat distances;  // first.size() x second.size(), CV_32F (Hamming counts are exact in a float)
  cv::batchDistance(first.descriptors, second.descriptors, distances, first.norm_type == cv::NORM_L2 ? CV_32F : CV_32S,
                    cv::noArray(), first.norm_type);
  distances.convertTo(distances, CV_32F);
  std::vector<TwoNearest> forward(first.size()), backward(second.size());
  for (int i = 0; i < distances.rows; ++i)
    for (int j = 0; j < distances.cols; ++j) {
      const float distance = distances.at<float>(i, j);
      forward[std::size_t(i)].offer(distance, j);
      backward[std::size_t(j)].offer(distance, i);
    }
  return mutualMatches(forward, backward, first, second, settings.ratio, gate);
}

}  // namespace bundletrack
