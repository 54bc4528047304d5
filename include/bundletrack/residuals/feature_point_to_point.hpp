#pragma once

#include <vector>

#include "bundletrack/residuals/residual.hpp"

namespace bundletrack {

/// Paper eq. 2: a feature correspondence (p_m in frame i, p_n in frame j) should be one object
/// point, r = T_i^-1 p_m - T_j^-1 p_n (object frame, 3-D). With right perturbations,
/// dr/dd_i = [-I, [T_i^-1 p_m]x] and dr/dd_j = -[-I, [T_j^-1 p_n]x].
struct FeaturePointToPoint {
  struct Input {
    const FrameFeatures& i;
    const FrameFeatures& j;
    const std::vector<FeatureMatch>& matches;  ///< first = i, second = j
  };
  static Input input(const EdgeView& edge) { return {edge.i.features, edge.j.features, edge.matches}; }

  template <RobustLoss Loss>
  void linearise(const Input& in, const SE3d& T_i, const SE3d& T_j, const Loss& loss, double weight,
                 PairSystem& system) const {
    for (const FeatureMatch& match : in.matches) {
      const Eigen::Vector3d p_m = in.i.points[std::size_t(match.first)].cast<double>();
      const Eigen::Vector3d p_n = in.j.points[std::size_t(match.second)].cast<double>();
      const Eigen::Vector3d r = T_i.inverse() * p_m - T_j.inverse() * p_n;
      const Eigen::Matrix<double, 3, 6> J_i = T_i.J_inverseAction_delta(p_m);
      const Eigen::Matrix<double, 3, 6> J_j = -T_j.J_inverseAction_delta(p_n);
      system.add<3>(r, J_i, J_j, loss, weight);
    }
  }
};

}  // namespace bundletrack
