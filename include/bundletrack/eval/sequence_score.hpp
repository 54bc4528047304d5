#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "bundletrack/eval/box_iou.hpp"
#include "bundletrack/eval/pose_metrics.hpp"

namespace bundletrack {

/// Accuracy of a tracked sequence against ground truth (docs/DESIGN.md section 6).
struct SequenceScore {
  double add_auc = 0.0;  ///< ADD AUC on [0, 10 cm], x100
  double adds_auc = 0.0;  ///< ADD-S AUC on [0, 10 cm], x100
  double deg5cm5 = 0.0;  ///< % of frames with rotation error < 5 deg and translation error < 5 cm
  double iou25 = 0.0;  ///< % of frames whose posed model boxes overlap by IoU > 25%
  double rotation_error_deg = 0.0;  ///< mean over frames with a pose (NaN when none has one)
  double translation_error_cm = 0.0;  ///< mean over frames with a pose (NaN when none has one)
  double final_add_cm = 0.0;  ///< ADD of the last frame: the drift at the end (inf when it has no pose)
  int frames = 0;
  int missing = 0;  ///< frames without an estimate: failures for every rate and AUC above
  std::size_t model_points = 0;  ///< the model's points ...
  std::size_t scored_points = 0;  ///< ... and those ADD and ADD-S were computed on (ScoringSubsample)
  double subsample_bound_cm = 0.0;  ///< each ADD-S distance exceeds the whole model's by at most this
};

/// A large model is scored on an even subsample: ADD and ADD-S average over every stride-th point,
/// and ADD-S takes its nearest neighbours among those points too, which makes each of its
/// distances larger than the whole model's by at most `bound` (the farthest any model point lies
/// from the subsample). A nearest-neighbour query against 10^6 points on a surface visits ~10^3 of
/// them at 1 cm, so the whole model would cost seconds per frame (bench/bench_scoring.cpp).
struct ScoringSubsample {
  std::vector<Eigen::Vector3f> points;
  std::size_t stride = 1;
  double bound = 0.0;  ///< metres
};

/// Models of up to this many points (the shared sequences' have 6.6k-24k) are scored whole.
inline constexpr std::size_t kMostScoredPoints = 50000;

inline ScoringSubsample scoringSubsample(const std::vector<Eigen::Vector3f>& model, std::size_t most = kMostScoredPoints) {
  ScoringSubsample subsample;
  subsample.stride = std::max<std::size_t>(1, (model.size() + most - 1) / std::max<std::size_t>(1, most));
  if (subsample.stride == 1) {
    subsample.points = model;
    return subsample;
  }
  for (std::size_t i = 0; i < model.size(); i += subsample.stride) subsample.points.push_back(model[i]);
  const KdTree3 tree(subsample.points);
  float farthest = 0.0f;
  for (const Eigen::Vector3f& p : model) farthest = std::max(farthest, tree.nearestSquaredDistance(p));
  subsample.bound = std::sqrt(double(farthest));
  return subsample;
}

/// Scores estimates against the truth; a frame without an estimate counts as a failure.
inline SequenceScore scoreSequence(const std::vector<Eigen::Vector3f>& model, const std::vector<SE3d>& truth,
                                   const std::vector<std::optional<SE3d>>& estimate) {
  SequenceScore score;
  score.frames = int(truth.size());
  score.model_points = model.size();
  if (truth.empty()) return score;
  const ObjectBox box = ObjectBox::bounding(model);
  const ScoringSubsample subsample = scoringSubsample(model);
  const std::vector<Eigen::Vector3f>& scored = subsample.points;
  score.scored_points = scored.size();
  score.subsample_bound_cm = 100.0 * subsample.bound;
  const KdTree3 tree(scored);
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<double> add, adds;
  int good = 0, overlapping = 0, present = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!estimate[i]) {
      ++score.missing;
      add.push_back(inf);
      adds.push_back(inf);
      continue;
    }
    const SE3d& T = *estimate[i];
    add.push_back(averageDistance(scored, truth[i], T));
    adds.push_back(averageDistanceSymmetric(scored, tree, truth[i], T));
    const double r = rotationErrorDeg(truth[i], T), t = translationError(truth[i], T);
    good += r < 5.0 && t < 0.05;
    overlapping += boxIoU(box, truth[i], T) > 0.25;
    score.rotation_error_deg += r;
    score.translation_error_cm += 100.0 * t;
    ++present;
  }
  score.rotation_error_deg = present > 0 ? score.rotation_error_deg / present : std::numeric_limits<double>::quiet_NaN();
  score.translation_error_cm = present > 0 ? score.translation_error_cm / present : std::numeric_limits<double>::quiet_NaN();
  score.add_auc = areaUnderCurve(add);
  score.adds_auc = areaUnderCurve(adds);
  score.deg5cm5 = 100.0 * good / double(truth.size());
  score.iou25 = 100.0 * overlapping / double(truth.size());
  score.final_add_cm = 100.0 * add.back();
  return score;
}

inline SequenceScore scoreSequence(const std::vector<Eigen::Vector3f>& model, const std::vector<SE3d>& truth,
                                   const std::vector<SE3d>& estimate) {
  return scoreSequence(model, truth, std::vector<std::optional<SE3d>>(estimate.begin(), estimate.end()));
}

}  // namespace bundletrack
