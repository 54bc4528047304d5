#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <numbers>
#include <utility>
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

/// The matched points of one RANSAC problem, side by side (pair k is match k).
struct MatchedPoints {
  std::vector<Eigen::Vector3f> first, second, first_normals, second_normals;

  MatchedPoints(const FrameFeatures& a, const FrameFeatures& b, const std::vector<FeatureMatch>& matches) {
    for (const FeatureMatch& m : matches) {
      first.push_back(a.points[std::size_t(m.first)]);
      second.push_back(b.points[std::size_t(m.second)]);
      first_normals.push_back(a.normals[std::size_t(m.first)]);
      second_normals.push_back(b.normals[std::size_t(m.second)]);
    }
  }
  std::size_t size() const { return first.size(); }
};

/// Paper IV-B's inlier test: the moved point within inlier_distance and the moved normal within
/// inlier_normal_angle_deg of its match.
struct InlierGate {
  float max_squared_distance;
  float cos_max_angle;

  explicit InlierGate(const RansacSettings& s)
      : max_squared_distance(s.inlier_distance * s.inlier_distance),
        cos_max_angle(std::cos(s.inlier_normal_angle_deg * std::numbers::pi_v<float> / 180.0f)) {}

  bool admits(const MatchedPoints& pairs, std::size_t k, const SE3f& T, const Eigen::Matrix3f& R) const {
    return (T * pairs.first[k] - pairs.second[k]).squaredNorm() < max_squared_distance &&
           (R * pairs.first_normals[k]).dot(pairs.second_normals[k]) > cos_max_angle;
  }
};

/// Counts the inliers of a batch of hypotheses on the CPU (in parallel when asked). The part of
/// RANSAC a backend may run elsewhere: prepare() sees the problem once, count() every batch;
/// counts[h] = 0 where valid[h] is false.
class CpuInlierCounter {
 public:
  explicit CpuInlierCounter(bool parallel = true) : parallel_(parallel) {}

  void prepare(const MatchedPoints&) {}

  void count(const MatchedPoints& pairs, const std::vector<SE3f>& hypotheses, const std::vector<char>& valid,
             const InlierGate& gate, std::vector<int>& counts) const {
    const auto body = [&](const cv::Range& range) {
      for (int h = range.start; h < range.end; ++h) {
        counts[std::size_t(h)] = 0;
        if (!valid[std::size_t(h)]) continue;
        const SE3f& T = hypotheses[std::size_t(h)];
        const Eigen::Matrix3f R = T.rotationMatrix();
        for (std::size_t k = 0; k < pairs.size(); ++k) counts[std::size_t(h)] += gate.admits(pairs, k, T, R);
      }
    };
    const cv::Range all(0, int(hypotheses.size()));
    if (parallel_) cv::parallel_for_(all, body);
    else body(all);
  }

 private:
  bool parallel_;
};

template <typename T>
concept InlierCounter = requires(T& counter, const MatchedPoints& pairs, const std::vector<SE3f>& hypotheses,
                                 const std::vector<char>& valid, const InlierGate& gate, std::vector<int>& counts) {
  counter.prepare(pairs);
  counter.count(pairs, hypotheses, valid, gate, counts);
};

/// RANSAC over 3-D feature matches (paper IV-B): 3-point samples, closed-form fit (kabsch), a match
/// is an inlier when the moved point lies within inlier_distance AND the moved normal within
/// inlier_normal_angle_deg. The trial count adapts to the best inlier ratio w found so far,
/// N = log(1 - confidence) / log(1 - w^3), capped at max_trials; ties go to the earliest trial, so
/// the result is deterministic whatever counts the inliers. The winner is refitted on its inliers
/// while the set grows.
template <InlierCounter Counter>
class BasicRansac {
 public:
  explicit BasicRansac(RansacSettings settings = {}, Counter counter = Counter())
      : settings_(settings), counter_(std::move(counter)) {}
  const RansacSettings& settings() const { return settings_; }

  RansacResult estimate(const FrameFeatures& first, const FrameFeatures& second,
                        const std::vector<FeatureMatch>& matches) const {
    RansacResult result;
    result.matches = matches.size();
    if (matches.size() < 3) return result;
    const MatchedPoints pairs(first, second, matches);
    const InlierGate gate(settings_);
    counter_.prepare(pairs);
    const int n = int(matches.size());
    const std::size_t batch = std::size_t(settings_.batch);
    std::vector<int> scores(batch);
    std::vector<SE3f> hypotheses(batch);
    std::vector<SE3d> fits(batch);
    std::vector<char> valid(batch);
    int best_score = 0, needed = settings_.max_trials;
    SE3d best;
    for (int start = 0; start < std::min(needed, settings_.max_trials); start += settings_.batch) {
      const int count = std::min(settings_.batch, settings_.max_trials - start);
      hypotheses.resize(std::size_t(count)), fits.resize(std::size_t(count)), valid.resize(std::size_t(count));
      scores.resize(std::size_t(count));
      for (int b = 0; b < count; ++b) {
        int sample[3];
        valid[std::size_t(b)] = drawSample(std::uint64_t(start + b), n, pairs, sample);
        if (!valid[std::size_t(b)]) continue;
        fits[std::size_t(b)] = kabsch(3, [&](std::size_t k) { return pairOf(pairs, sample[k]); });
        hypotheses[std::size_t(b)] = fits[std::size_t(b)].cast<float>();
      }
      counter_.count(pairs, hypotheses, valid, gate, scores);
      for (int b = 0; b < count; ++b) {
        if (scores[std::size_t(b)] <= best_score) continue;
        best_score = scores[std::size_t(b)];
        best = fits[std::size_t(b)];
        const double w = double(best_score) / n;
        needed = w >= 1.0 ? 0 : int(std::ceil(std::log(1.0 - settings_.confidence) / std::log(1.0 - w * w * w)));
      }
      result.trials = start + count;
    }
    if (best_score < 3) return result;
    // Least-squares refit on the consensus set, repeated while the set changes and does not shrink;
    // the result is always the refit of the reported inliers.
    std::vector<int> inliers = inliersOf(pairs, gate, best);
    for (int refit = 0; refit < 5; ++refit) {
      best = kabsch(inliers.size(), [&](std::size_t k) { return pairOf(pairs, inliers[k]); });
      std::vector<int> next = inliersOf(pairs, gate, best);
      if (next.size() < inliers.size() || next == inliers) break;
      inliers = std::move(next);
    }
    result.T_second_first = best;
    result.inliers = std::move(inliers);
    return result;
  }

 private:
  static std::pair<const Eigen::Vector3f&, const Eigen::Vector3f&> pairOf(const MatchedPoints& pairs, int k) {
    return {pairs.first[std::size_t(k)], pairs.second[std::size_t(k)]};
  }

  static std::vector<int> inliersOf(const MatchedPoints& pairs, const InlierGate& gate, const SE3d& T) {
    const SE3f Tf = T.cast<float>();
    const Eigen::Matrix3f R = Tf.rotationMatrix();
    std::vector<int> inliers;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      if (gate.admits(pairs, k, Tf, R)) inliers.push_back(int(k));
    return inliers;
  }

  bool drawSample(std::uint64_t trial, int n, const MatchedPoints& pairs, int sample[3]) const {
    std::uint64_t state = detail::splitmix64(settings_.seed ^ detail::splitmix64(trial));
    for (int k = 0; k < 3; ++k) {
      state = detail::splitmix64(state);
      sample[k] = int(state % std::uint64_t(n));
    }
    if (sample[0] == sample[1] || sample[0] == sample[2] || sample[1] == sample[2]) return false;
    // Reject near-collinear samples in either frame: the smallest triangle height must exceed the spread.
    for (const std::vector<Eigen::Vector3f>* points : {&pairs.first, &pairs.second}) {
      const auto point = [&](int k) -> const Eigen::Vector3f& { return (*points)[std::size_t(sample[k])]; };
      const Eigen::Vector3f ab = point(1) - point(0), ac = point(2) - point(0), bc = point(2) - point(1);
      const float longest = std::max({ab.norm(), ac.norm(), bc.norm()});
      if (longest <= 0.0f || ab.cross(ac).norm() / longest < settings_.min_sample_spread) return false;
    }
    return true;
  }

  RansacSettings settings_;
  mutable Counter counter_;  // a backend may keep device buffers between calls
};

/// RANSAC with the inliers counted on the CPU (in parallel unless settings.parallel is false).
class Ransac : public BasicRansac<CpuInlierCounter> {
 public:
  explicit Ransac(RansacSettings settings = {}) : BasicRansac(settings, CpuInlierCounter(settings.parallel)) {}
};

/// What the tracker asks of its robust registration (Ransac, cuda::Ransac): built from the
/// RANSAC settings, it estimates the pose between two frames' features from their matches.
template <typename T>
concept FeatureRegistration =
    std::constructible_from<T, RansacSettings> &&
    requires(const T& registration, const FrameFeatures& features, const std::vector<FeatureMatch>& matches) {
      { registration.estimate(features, features, matches) } -> std::same_as<RansacResult>;
    };

}  // namespace bundletrack
