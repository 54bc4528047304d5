#pragma once

#include <Eigen/Geometry>

#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/residuals/residual.hpp"

namespace bundletrack {

/// Paper eq. 3: dense point-to-plane distances by projective association on the surface grids.
/// A point p_s of grid s is moved into frame t (T_t T_s^-1 p_s), projected with t's grid camera,
/// and paired with the point p_t seen at that cell; the pair counts when it passes `gate`, widened
/// for the two grids' noise (NoiseScale::between). The
/// residual, in the object frame with m = R_s^T n_s,
///   r = m . (T_t^-1 p_t - T_s^-1 p_s),
/// has dr/dd_s = [m^T, (b x m)^T] with b = T_t^-1 p_t, and dr/dd_t = -dr/dd_s (it depends on the
/// relative pose only). Both directions of an edge are summed, as eq. 1 sums over ordered pairs.
/// Each residual stands for the step^2 pixels its cell covers: its weight is sampleWeight(s),
/// (step / 4)^2, so that the term is the same integral over the surface at any grid step and its
/// balance with the feature term stays the one set for the original code's step 4.
struct DensePointToPlane {
  SurfaceGate gate;  ///< the original code's 2 cm / 45 degrees

  static constexpr int kReferenceStep = 4;
  static double sampleWeight(const SurfaceGrid& s) {
    return double(s.step * s.step) / double(kReferenceStep * kReferenceStep);
  }

  struct Input {
    const SurfaceGrid& i;
    const SurfaceGrid& j;
  };
  static Input input(const EdgeView& edge) { return {edge.i.surface, edge.j.surface}; }

  template <RobustLoss Loss>
  void linearise(const Input& in, const SE3d& T_i, const SE3d& T_j, const Loss& loss, double weight,
                 PairSystem& system) const {
    addDirected(in.i, in.j, T_i, T_j, loss, weight * sampleWeight(in.i), false, system);
    addDirected(in.j, in.i, T_j, T_i, loss, weight * sampleWeight(in.j), true, system);
    system.finish();
  }

 private:
  template <typename Loss>
  void addDirected(const SurfaceGrid& s, const SurfaceGrid& t, const SE3d& T_s, const SE3d& T_t, const Loss& loss,
                   double weight, bool swapped, PairSystem& system) const {
    // Rigid maps as matrices: the loop applies each to every point.
    const auto affine = [](const SE3d& T) { return Eigen::Isometry3d(T.matrix()); };
    const Eigen::Isometry3d T_s_inv = affine(T_s.inverse()), T_t_inv = affine(T_t.inverse());
    const Eigen::Isometry3d T_t_s = affine(T_t * T_s.inverse()), T_s_t = affine(T_s * T_t.inverse());
    const Eigen::Matrix3d R_s_inv = T_s_inv.linear(), R_s_t = T_s_t.linear();
    const SurfaceGate::Bounds<double> bounds = gate.widened(NoiseScale::between(s.noise_scale, t.noise_scale)).bounds<double>();
    for (const cv::Point& cell : s.cells) {
      const cv::Vec3f& ps = s.point(cell);
      const Eigen::Vector3d p_s(ps[0], ps[1], ps[2]);
      int u = 0, v = 0;
      if (!t.camera.pixelOf(T_t_s * p_s, u, v) || !t.inside(u, v)) continue;
      const cv::Vec3f& pt = t.point(u, v);
      if (pt[2] <= 0.0f) continue;
      const Eigen::Vector3d p_t(pt[0], pt[1], pt[2]);
      if ((T_s_t * p_t - p_s).squaredNorm() > bounds.max_squared_distance) continue;  // the cheap test first
      const cv::Vec3f& ns = s.normal(cell);
      const cv::Vec3f& nt = t.normal(u, v);
      const Eigen::Vector3d n_s(ns[0], ns[1], ns[2]);
      if ((R_s_t * Eigen::Vector3d(nt[0], nt[1], nt[2])).dot(n_s) < bounds.cos_max_angle) continue;
      const Eigen::Vector3d m = R_s_inv * n_s, a = T_s_inv * p_s, b = T_t_inv * p_t;
      Eigen::Matrix<double, 1, 6> J_s;
      J_s.leftCols<3>() = m.transpose();
      J_s.rightCols<3>() = b.cross(m).transpose();
      // J_i is J_s, or -J_s when s is the edge's second node.
      system.addRelative(m.dot(b - a), swapped ? Eigen::Matrix<double, 1, 6>(-J_s) : J_s, loss, weight);
    }
  }
};

}  // namespace bundletrack
