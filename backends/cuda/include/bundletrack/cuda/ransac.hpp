#pragma once

#include <memory>
#include <vector>

#include "bundletrack/registration/ransac.hpp"

namespace bundletrack::cuda {

/// RANSAC's inlier counting on the GPU: the matched points are uploaded once per problem, and each
/// batch of hypotheses is scored by one block per hypothesis (threads over the matches, a block
/// sum). Every count lands in its own slot and the host picks the best (earliest on ties), so
/// there is no race between blocks for the best hypothesis (the original code's bug).
class InlierCounter {
 public:
  InlierCounter();
  void prepare(const MatchedPoints& pairs);
  void count(const MatchedPoints& pairs, const std::vector<SE3f>& hypotheses, const std::vector<char>& valid,
             const InlierGate& gate, std::vector<int>& counts) const;

 private:
  struct Workspace;
  std::shared_ptr<Workspace> workspace_;
};

/// bundletrack::Ransac with the inliers counted on the GPU: the same samples, fits, adaptive stop
/// and refit, so it returns the same result. Satisfies FeatureRegistration.
class Ransac : public BasicRansac<InlierCounter> {
 public:
  explicit Ransac(RansacSettings settings = {}) : BasicRansac(settings) {}
};

}  // namespace bundletrack::cuda
