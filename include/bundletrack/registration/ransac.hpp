#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/core/execution.hpp"
#include "bundletrack/features/frame_features.hpp"
#include "bundletrack/registration/feature_registration.hpp"
#include "bundletrack/registration/kabsch.hpp"
#include "bundletrack/registration/ransac_trial.hpp"

namespace bundletrack {

struct RansacSettings {
  float inlier_distance = 0.005f;  ///< metres (paper IV-B: delta = 5 mm)
  float inlier_normal_angle_deg = 45.0f;  ///< paper IV-B: alpha = 45 degrees (missing in the original code)
  int max_trials = 2000;  ///< cap on hypotheses (the original code always ran 2000)
  double confidence = 0.999;  ///< stop once a better hypothesis is this unlikely to have been missed
  float min_sample_spread = 0.005f;  ///< metres; smallest height of a sample triangle (rejects near-collinear ones)
  int batch = 64;  ///< hypotheses scored together
  Execution execution = Execution::Parallel;  ///< how the CPU scores a batch (the GPU scores it in one launch)
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
  std::pair<const Eigen::Vector3f&, const Eigen::Vector3f&> pair(std::size_t k) const { return {first[k], second[k]}; }
};

/// Paper IV-B's inlier test: the moved point within inlier_distance (widened by the two frames'
/// noise, NoiseScale::between) and the moved normal within inlier_normal_angle_deg of its match.
struct InlierGate {
  float max_squared_distance;
  float cos_max_angle;

  InlierGate(const RansacSettings& s, double noise_scale)
      : max_squared_distance(float(s.inlier_distance * noise_scale * s.inlier_distance * noise_scale)),
        cos_max_angle(cosOfDegrees<float>(s.inlier_normal_angle_deg)) {}

  bool admits(const MatchedPoints& pairs, std::size_t k, const SE3f& T, const Eigen::Matrix3f& R) const {
    return (T * pairs.first[k] - pairs.second[k]).squaredNorm() < max_squared_distance &&
           (R * pairs.first_normals[k]).dot(pairs.second_normals[k]) > cos_max_angle;
  }
};

/// Draws trial k's sample (trialSample), rejects it when two matches coincide or its triangle is
/// near-collinear in either frame (wellSpread, min_sample_spread); false for a rejected sample.
inline bool drawTrial(const MatchedPoints& pairs, const RansacSettings& settings, std::uint64_t trial, int sample[3]) {
  if (!trialSample(settings.seed, trial, int(pairs.size()), sample)) return false;
  for (const std::vector<Eigen::Vector3f>* points : {&pairs.first, &pairs.second}) {
    const auto at = [&](int k) { return (*points)[std::size_t(sample[k])].data(); };
    if (!wellSpread(at(0), at(1), at(2), settings.min_sample_spread)) return false;
  }
  return true;
}

/// The part of RANSAC a backend may run elsewhere: for trials first .. first + count - 1, draw the
/// sample (drawTrial), fit it (the least-squares rigid fit of its three pairs) and count the
/// fit's inliers. prepare() sees the problem once; score() fills fits[b], valid[b] (false for a
/// rejected sample) and scores[b] (0 where not valid) for b < count.
template <typename T>
concept TrialScorer = requires(T& scorer, const MatchedPoints& pairs, const RansacSettings& settings,
                               const InlierGate& gate, std::vector<SE3d>& fits, std::vector<char>& valid,
                               std::vector<int>& scores) {
  scorer.prepare(pairs);
  scorer.score(pairs, settings, gate, 0, 1, fits, valid, scores);
};

/// Trials on the CPU: samples and kabsch fits one by one, inliers counted per hypothesis
/// (settings.execution: in parallel, or one by one).
class CpuTrialScorer {
 public:
  static constexpr bool kConcurrentCalls = true;  ///< keeps no state between calls (ConcurrentCalls)

  void prepare(const MatchedPoints&) {}

  void score(const MatchedPoints& pairs, const RansacSettings& settings, const InlierGate& gate, int first, int count,
             std::vector<SE3d>& fits, std::vector<char>& valid, std::vector<int>& scores) const {
    fits.resize(std::size_t(count)), valid.resize(std::size_t(count)), scores.resize(std::size_t(count));
    std::vector<SE3f> hypotheses(static_cast<std::size_t>(count));
    for (int b = 0; b < count; ++b) {
      int sample[3];
      valid[std::size_t(b)] = drawTrial(pairs, settings, std::uint64_t(first + b), sample);
      if (!valid[std::size_t(b)]) continue;
      fits[std::size_t(b)] = kabsch(3, [&](std::size_t k) { return pairs.pair(std::size_t(sample[k])); });
      hypotheses[std::size_t(b)] = fits[std::size_t(b)].cast<float>();
    }
    forEachIndex(settings.execution, count, [&](int h) {
      scores[std::size_t(h)] = 0;
      if (!valid[std::size_t(h)]) return;
      const SE3f& T = hypotheses[std::size_t(h)];
      const Eigen::Matrix3f R = T.rotationMatrix();
      for (std::size_t k = 0; k < pairs.size(); ++k) scores[std::size_t(h)] += gate.admits(pairs, k, T, R);
    });
  }
};

/// RANSAC over 3-D feature matches (paper IV-B): 3-point samples, closed-form fit (kabsch), a match
/// is an inlier when the moved point lies within inlier_distance (widened for the sensor's noise) AND the moved normal within
/// inlier_normal_angle_deg. The trial count adapts to the best inlier ratio w found so far,
/// N = log(1 - confidence) / log(1 - w^3), capped at max_trials; ties go to the earliest trial, so
/// the result is deterministic whatever counts the inliers. The winner is refitted on its inliers
/// while the set grows.
template <TrialScorer Scorer>
class BasicRansac {
 public:
  /// Concurrent estimate() calls are safe where the scorer's are (ConcurrentCalls).
  static constexpr bool kConcurrentCalls = ConcurrentCalls<Scorer>;

  explicit BasicRansac(RansacSettings settings = {}, Scorer scorer = Scorer())
      : settings_(settings), scorer_(std::move(scorer)) {}
  const RansacSettings& settings() const { return settings_; }

  RansacResult estimate(const FrameFeatures& first, const FrameFeatures& second,
                        const std::vector<FeatureMatch>& matches) const {
    RansacResult result;
    result.matches = matches.size();
    if (matches.size() < 3) return result;
    const MatchedPoints pairs(first, second, matches);
    const InlierGate gate(settings_, NoiseScale::between(first.noise_scale, second.noise_scale));
    scorer_.prepare(pairs);
    const int n = int(matches.size());
    std::vector<SE3d> fits;
    std::vector<char> valid;
    std::vector<int> scores;
    int best_score = 0, needed = settings_.max_trials;
    SE3d best;
    for (int start = 0; start < std::min(needed, settings_.max_trials); start += settings_.batch) {
      const int count = std::min(settings_.batch, settings_.max_trials - start);
      scorer_.score(pairs, settings_, gate, start, count, fits, valid, scores);
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
      best = kabsch(inliers.size(), [&](std::size_t k) { return pairs.pair(std::size_t(inliers[k])); });
      std::vector<int> next = inliersOf(pairs, gate, best);
      if (next.size() < inliers.size() || next == inliers) break;
      inliers = std::move(next);
    }
    result.T_second_first = best;
    result.inliers = std::move(inliers);
    return result;
  }

 private:
  static std::vector<int> inliersOf(const MatchedPoints& pairs, const InlierGate& gate, const SE3d& T) {
    const SE3f Tf = T.cast<float>();
    const Eigen::Matrix3f R = Tf.rotationMatrix();
    std::vector<int> inliers;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      if (gate.admits(pairs, k, Tf, R)) inliers.push_back(int(k));
    return inliers;
  }

  RansacSettings settings_;
  mutable Scorer scorer_;  // a backend may keep device buffers between calls
};

/// RANSAC with its trials on the CPU.
using Ransac = BasicRansac<CpuTrialScorer>;

}  // namespace bundletrack
