#pragma once

// A residual term that exists only in the tests, to show what a new term takes: this header and
// the Term that names it in an energy (test_residual_plugin.cpp).

#include <vector>

#include "bundletrack/residuals/residual.hpp"

namespace bundletrack::testing {

/// Feature point-to-plane: a correspondence (p_m in frame i, p_n with normal n in frame j) should
/// put p_m on the plane of p_n: r = n . (T_j T_i^-1 p_m - p_n). In the object frame,
/// r = m . (a - b) with a = T_i^-1 p_m, b = T_j^-1 p_n, m = R_j^T n; it depends on the relative
/// pose only, and dr/dd_i = -[m^T, (a x m)^T] = -dr/dd_j.
struct FeaturePointToPlane {
  struct Input {
    const FrameFeatures& i;
    const FrameFeatures& j;
    const std::vector<FeatureMatch>& matches;
  };
  static Input input(const EdgeView& edge) { return {edge.i.features, edge.j.features, edge.matches}; }

  template <RobustLoss Loss>
  void linearise(const Input& in, const SE3d& T_i, const SE3d& T_j, const Loss& loss, double weight,
                 PairSystem& system) const {
    for (const FeatureMatch& match : in.matches) {
      const Eigen::Vector3d a = T_i.inverse() * in.i.points[std::size_t(match.first)].cast<double>();
      const Eigen::Vector3d b = T_j.inverse() * in.j.points[std::size_t(match.second)].cast<double>();
      const Eigen::Vector3d m = T_j.rotation().inverse() * in.j.normals[std::size_t(match.second)].cast<double>();
      Eigen::Matrix<double, 1, 6> J_i;
      J_i.leftCols<3>() = -m.transpose();
      J_i.rightCols<3>() = -a.cross(m).transpose();
      system.addRelative(m.dot(a - b), J_i, loss, weight);
    }
    system.finish();
  }
};

}  // namespace bundletrack::testing
