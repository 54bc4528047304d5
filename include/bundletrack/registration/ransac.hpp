#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/features/frame_features.hpp"
#include "bundletrack/registration/kabsch.hpp"

namespace bundletrack {

struct RansacSettings {
  float inlier_distance = 0.005f;  ///< metres (paper IV-B: delta = 5 mm)
  float inlier_normal_angle_deg = 45.0f;  ///< paper IV-B: alpha = 45 degrees (missing in the original code)
  int max_trials = 2000;  ///< cap on hypotheses (the original code always ran 2000)
  double confidence = 0.999;  ///< stop once a better hypothesis is this unlikely to have been missed
  float min_sample_spread = 0.005f;  ///< metres; smallest height of a sample triangle (rejects near-collinear ones)
  int batch = 64;  ///< hypotheses scored together (in parallel when `parallel`)
  bool parallel = true;
  std::uint64_t seed = 0;
};

struct RansacResult {
  SE3d T_second_first;  ///< maps first-frame points onto second-frame points
  std::vector<int> inliers;  ///< indices into the matches
  std::size_t matches = 0;
  int trials = 0;

  bool found() const { return !inliers.empty(); }
  double inlierRatio() const { return matches == 0 ? 0.0 : double(inliers.size()) / double(matches); }
};

namespace detail {

/// SplitMix64: trial k's sample depends only on (seed, k), whatever the thread schedule.
inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace detail

/// RANSAC over 3-D feature matches (paper IV-B): 3-point samples, closed-form fit (kabsch), a match
/// is an inlier when the moved point lies within inlier_distance AND the moved normal within
/// inlier_normal_angle_deg. The trial count adapts to the best inlier ratio w found so far,
/// N = log(1 - confidence) / log(1 - w^3), capped at max_trials; ties go to the earliest trial, so
/// the result is deterministic. The winner is refitted on its inliers while the set grows.
class Ransac {
 public:
  explicit Ransac(RansacSettings settings = {}) : settings_(settings) {}
  const RansacSettings& settings() const { return settings_; }

  RansacResult estimate(const FrameFeatures& first, const FrameFeatures& second,
                        const std::vector<FeatureMatch>& matches) const {
    RansacResult result;
    result.matches = matches.size();
    if (matches.size() < 3) return result;
    const int n = int(matches.size());
    std::vector<int> scores(std::size_t(settings_.batch));
    std::vector<SE3d> hypotheses(std::size_t(settings_.batch));
    int best_score = 0, needed = settings_.max_trials;
    SE3d best;
    for (int start = 0; start < std::min(needed, settings_.max_trials); start += settings_.batch) {
      const int count = std::min(settings_.batch, settings_.max_trials - start);
      const auto score_trials = [&](const cv::Range& range) {
        for (int b = range.start; b < range.end; ++b) {
          scores[b] = 0;
          int sample[3];
          if (!drawSample(std::uint64_t(start + b), n, first, second, matches, sample)) continue;
          hypotheses[b] = kabsch(3, [&](std::size_t k) { return pairOf(first, second, matches[sample[k]]); });
          scores[b] = countInliers(first, second, matches, hypotheses[b], nullptr);
        }
      };
      if (settings_.parallel) cv::parallel_for_(cv::Range(0, count), score_trials);
      else score_trials(cv::Range(0, count));
      for (int b = 0; b < count; ++b) {
        if (scores[b] <= best_score) continue;
        best_score = scores[b];
        best = hypotheses[b];
        const double w = double(best_score) / n;
        needed = w >= 1.0 ? 0 : int(std::ceil(std::log(1.0 - settings_.confidence) / std::log(1.0 - w * w * w)));
      }
      result.trials = start + count;
    }
    if (best_score < 3) return result;
    // Least-squares refit on the consensus set, repeated while the set changes and does not shrink;
    // the result is always the refit of the reported inliers.
    std::vector<int> inliers;
    countInliers(first, second, matches, best, &inliers);
    for (int refit = 0; refit < 5; ++refit) {
      best = kabsch(inliers.size(), [&](std::size_t k) { return pairOf(first, second, matches[inliers[k]]); });
      std::vector<int> next;
      countInliers(first, second, matches, best, &next);
      if (next.size() < inliers.size() || next == inliers) break;
      inliers = std::move(next);
    }
    result.T_second_first = best;
    result.inliers = std::move(inliers);
    return result;
  }

 private:
  static std::pair<const Eigen::Vector3f&, const Eigen::Vector3f&> pairOf(const FrameFeatures& first,
                                                                        const FrameFeatures& second,
                                                                        const FeatureMatch& m) {
    return {first.points[m.first], second.points[m.second]};
  }

  bool drawSample(std::uint64_t trial, int n, const FrameFeatures& first, const FrameFeatures& second,
                  const std::vector<FeatureMatch>& matches, int sample[3]) const {
    std::uint64_t state = detail::splitmix64(settings_.seed ^ detail::splitmix64(trial));
    for (int k = 0; k < 3; ++k) {
      state = detail::splitmix64(state);
      sample[k] = int(state % std::uint64_t(n));
    }
    if (sample[0] == sample[1] || sample[0] == sample[2] || sample[1] == sample[2]) return false;
    // Reject near-collinear samples in either frame: the smallest triangle height must exceed the spread.
    for (const FrameFeatures* f : {&first, &second}) {
      const bool is_first = f == &first;
      const auto point = [&](int k) -> const Eigen::Vector3f& {
        return is_first ? f->points[matches[sample[k]].first] : f->points[matches[sample[k]].second];
      };
      const Eigen::Vector3f ab = point(1) - point(0), ac = point(2) - point(0), bc = point(2) - point(1);
      const float longest = std::max({ab.norm(), ac.norm(), bc.norm()});
      if (longest <= 0.0f || ab.cross(ac).norm() / longest < settings_.min_sample_spread) return false;
    }
    return true;
  }

  int countInliers(const FrameFeatures& first, const FrameFeatures& second, const std::vector<FeatureMatch>& matches,
                   const SE3d& T, std::vector<int>* inliers) const {
    const SE3f Tf = T.cast<float>();
    const Eigen::Matrix3f R = Tf.rotationMatrix();
    const float max_sq = settings_.inlier_distance * settings_.inlier_distance;
    const float cos_max = std::cos(settings_.inlier_normal_angle_deg * std::numbers::pi_v<float> / 180.0f);
    int count = 0;
    for (int k = 0; k < int(matches.size()); ++k) {
      const auto& m = matches[k];
      if ((Tf * first.points[m.first] - second.points[m.second]).squaredNorm() >= max_sq) continue;
      if ((R * first.normals[m.first]).dot(second.normals[m.second]) <= cos_max) continue;
      ++count;
      if (inliers) inliers->push_back(k);
    }
    return count;
  }

  RansacSettings settings_;
};

}  // namespace bundletrack
