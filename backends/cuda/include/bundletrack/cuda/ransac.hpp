#pragma once

#include <memory>
#include <vector>

#include "bundletrack/registration/ransac.hpp"

namespace bundletrack::cuda {

/// RANSAC's trials on the GPU: the matched pairs are uploaded once per problem; for each batch one
/// thread per trial draws the sample (the CPU's drawTrial rules, so the same samples) and fits it
/// (Horn's closed form, the same optimum as kabsch), then one block per trial counts its inliers.
/// Every count lands in its own slot and the host picks the best (earliest on ties), so there is
/// no race between blocks for the best hypothesis (the original code's bug). Satisfies TrialScorer.
class TrialScorer {
 public:
  TrialScorer();
  void prepare(const MatchedPoints& pairs);
  void score(const MatchedPoints& pairs, const RansacSettings& settings, const InlierGate& gate, int first, int count,
             std::vector<SE3d>& fits, std::vector<char>& valid, std::vector<int>& scores) const;

 private:
  struct Workspace;
  std::shared_ptr<Workspace> workspace_;
};

/// bundletrack::Ransac with its trials drawn, fitted and scored on the GPU: the same samples,
/// adaptive stop and refit, so it returns the CPU's result up to float rounding at the inlier
/// boundary. Satisfies FeatureRegistration.
using Ransac = BasicRansac<TrialScorer>;

}  // namespace bundletrack::cuda
