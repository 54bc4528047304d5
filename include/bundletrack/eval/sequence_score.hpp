#pragma once

#include <vector>

#include "bundletrack/eval/pose_metrics.hpp"

namespace bundletrack {

/// Accuracy of a tracked sequence against ground truth (DESIGN.md section 6).
struct SequenceScore {
  double add_auc = 0.0;  ///< ADD AUC on [0, 10 cm], x100
  double adds_auc = 0.0;  ///< ADD-S AUC on [0, 10 cm], x100
  double deg5cm5 = 0.0;  ///< % of frames with rotation error < 5 deg and translation error < 5 cm
  double rotation_error_deg = 0.0;  ///< mean
  double translation_error_cm = 0.0;  ///< mean
  double final_add_cm = 0.0;  ///< ADD of the last frame: the drift at the end
  int frames = 0;
};

inline SequenceScore scoreSequence(const std::vector<Eigen::Vector3f>& model, const std::vector<SE3d>& truth,
                                   const std::vector<SE3d>& estimate) {
  SequenceScore score;
  score.frames = int(truth.size());
  if (truth.empty()) return score;
  const KdTree3 tree(model);
  std::vector<double> add, adds;
  int good = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    add.push_back(averageDistance(model, truth[i], estimate[i]));
    adds.push_back(averageDistanceSymmetric(model, tree, truth[i], estimate[i]));
    const double r = rotationErrorDeg(truth[i], estimate[i]), t = translationError(truth[i], estimate[i]);
    good += r < 5.0 && t < 0.05;
    score.rotation_error_deg += r / double(truth.size());
    score.translation_error_cm += 100.0 * t / double(truth.size());
  }
  score.add_auc = areaUnderCurve(add);
  score.adds_auc = areaUnderCurve(adds);
  score.deg5cm5 = 100.0 * good / double(truth.size());
  score.final_add_cm = 100.0 * add.back();
  return score;
}

}  // namespace bundletrack
