#pragma once

#include <memory>
#include <span>

#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/robust/loss_kind.hpp"

namespace bundletrack::cuda {

/// The dense point-to-plane term (paper eq. 3) on the GPU: the association, gates, residual and
/// Jacobian of bundletrack::DensePointToPlane, robust weights and each edge's normal equations
/// accumulated in double on the device. lineariseAll() does every direction of every edge of a
/// graph in one kernel launch (the energy calls it once per Gauss-Newton iteration). Surface grids
/// are uploaded once and stay on the device while they are in use (the 64 most recently used).
/// Satisfies BatchResidual, so Energy<..., Term<cuda::DensePointToPlane, HuberLoss>> composes.
class DensePointToPlane {
 public:
  SurfaceGate gate;  ///< the original code's 2 cm / 45 degrees
  using Input = bundletrack::DensePointToPlane::Input;
  static Input input(const EdgeView& edge) { return bundletrack::DensePointToPlane::input(edge); }

  DensePointToPlane();

  template <RobustLoss Loss>
  void linearise(const Input& in, const SE3d& T_i, const SE3d& T_j, const Loss& loss, double weight,
                 PairSystem& system) const {
    const GraphEdge edge{0, 1};
    const SE3d poses[2] = {T_i, T_j};
    lineariseAllWith(std::span(&in, 1), std::span(&edge, 1), poses, lossParameters(loss), weight, std::span(&system, 1));
  }

  /// systems[e] += the residuals of edge e (inputs[e], at poses[edges[e].i], poses[edges[e].j]),
  /// for all edges in one launch.
  template <RobustLoss Loss>
  void lineariseAll(std::span<const Input> inputs, std::span<const GraphEdge> edges, std::span<const SE3d> poses,
                    const Loss& loss, double weight, std::span<PairSystem> systems) const {
    lineariseAllWith(inputs, edges, poses, lossParameters(loss), weight, systems);
  }

 private:
  void lineariseAllWith(std::span<const Input> inputs, std::span<const GraphEdge> edges, std::span<const SE3d> poses,
                        const LossParameters& loss, double weight, std::span<PairSystem> systems) const;

  struct Workspace;
  std::shared_ptr<Workspace> workspace_;
};

}  // namespace bundletrack::cuda
