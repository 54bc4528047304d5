#pragma once

#include <map>
#include <utility>

#include <Eigen/Core>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/solvers/pair_system.hpp"

namespace bundletrack {

/// When an edge between two keyframes is linearised again. Zero: at every Gauss-Newton step, as
/// the paper and the original code do.
struct RelinearisationSettings {
  double max_translation = 0.0;  ///< metres a keyframe may move since its edge's linearisation ...
  double max_rotation = 0.0;  ///< ... and radians it may turn
};

/// The normal equations of edges between keyframes of the pool, kept across Gauss-Newton steps and
/// frames while neither keyframe moves beyond RelinearisationSettings since (lazy relinearisation,
/// as iSAM2 relinearises only variables whose change passes a threshold: Kaess et al., IJRR 2012).
/// Between two keyframes only their poses change from frame to frame (their points, features and
/// correspondences are fixed), and the graph moves them by micrometres once they have settled, so
/// the current frame's edges are the only ones that need their residuals every step. A kept system
/// is moved to the new poses along its linear model (docs/DESIGN.md section 4): with d the right
/// perturbations from the poses it was made at, b <- b + H d and cost <- cost + 2 b.d + d^T H d
/// (the cost is sum rho, whose gradient is 2b and Hessian 2H). Forgotten with an evicted keyframe.
class EdgeLinearisationCache {
 public:
  explicit EdgeLinearisationCache(const RelinearisationSettings& settings = {}) : settings_(settings) {}

  bool enabled() const { return settings_.max_translation > 0.0 || settings_.max_rotation > 0.0; }

  /// Keyframes a and b's system at poses T_a, T_b from the one kept for them, when there is one
  /// and neither keyframe moved beyond the settings since it was made.
  bool reuse(int a, int b, const SE3d& T_a, const SE3d& T_b, PairSystem& out) const {
    const auto found = kept_.find({a, b});
    if (found == kept_.end()) return false;
    const Kept& kept = found->second;
    Eigen::Matrix<double, 12, 1> d;
    d.head<6>() = (kept.T_a.inverse() * T_a).log();
    d.tail<6>() = (kept.T_b.inverse() * T_b).log();
    if (!withinSettings(d.head<6>()) || !withinSettings(d.tail<6>())) return false;
    out = kept.system;
    out.b.noalias() += kept.system.H * d;
    out.cost += 2.0 * kept.system.b.dot(d) + d.dot(kept.system.H * d);
    return true;
  }

  void keep(int a, int b, const SE3d& T_a, const SE3d& T_b, const PairSystem& system) {
    kept_.insert_or_assign(std::make_pair(a, b), Kept{T_a, T_b, system});
  }

  void forget(int keyframe_id) {
    for (auto it = kept_.begin(); it != kept_.end();)
      it = it->first.first == keyframe_id || it->first.second == keyframe_id ? kept_.erase(it) : std::next(it);
  }

  void clear() { kept_.clear(); }

 private:
  struct Kept {
    SE3d T_a, T_b;
    PairSystem system;
  };

  bool withinSettings(const Eigen::Matrix<double, 6, 1>& d) const {
    return d.head<3>().norm() <= settings_.max_translation && d.tail<3>().norm() <= settings_.max_rotation;
  }

  RelinearisationSettings settings_;
  std::map<std::pair<int, int>, Kept> kept_;
};

}  // namespace bundletrack
