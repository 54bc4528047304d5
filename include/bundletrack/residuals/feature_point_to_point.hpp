#pragma once

#include "bundletrack/residuals/pair_system.hpp"

namespace bundletrack {

/// Paper eq. 2: a feature correspondence (p_m in frame i, p_n in frame j) should be one object
/// point, r = T_i^-1 p_m - T_j^-1 p_n (object frame, 3-D). With right perturbations,
/// dr/dd_i = [-I, [T_i^-1 p_m]x] and dr/dd_j = -[-I, [T_j^-1 p_n]x].
struct FeaturePointToPoint {
  template <RobustLoss Loss>
  void linearise(const PairInput& in, const Loss& loss, double weight, PairSystem& system) const {
    for (const FeatureMatch& match : in.matches) {
      const Eigen::Vector3d p_m = in.i.features.points[match.first].cast<double>();
      const Eigen::Vector3d p_n = in.j.features.points[match.second].cast<double>();
      const Eigen::Vector3d r = in.T_i.inverse() * p_m - in.T_j.inverse() * p_n;
      const Eigen::Matrix<double, 3, 6> J_i = in.T_i.J_inverseAction_delta(p_m);
      const Eigen::Matrix<double, 3, 6> J_j = -in.T_j.J_inverseAction_delta(p_n);
      system.add<3>(r, J_i, J_j, loss, weight);
    }
  }
};

}  // namespace bundletrack
