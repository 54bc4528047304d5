#pragma once

#include <Eigen/Geometry>

#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/core/intensity_image.hpp"
#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/residuals/image_jacobian.hpp"
#include "bundletrack/residuals/residual.hpp"

namespace bundletrack {

/// Beyond the paper: dense brightness constancy (docs/DESIGN.md section 7). A point p_s of grid s
/// is the object point a = T_s^-1 p_s; seen from frame t it lands at q = T_t a, pixel pi(q), and
/// should look as bright there as in s:
///   r = I_t(pi(q)) - I_s(p_s),
/// with, for right perturbations, dr/dd_t = [w^T, (a x w)^T], w = R_t^T (dpi/dq)^T grad I_t, and
/// dr/dd_s = -dr/dd_t (r depends on the relative pose only). The point counts where t sees it: its
/// projection is associated with t's surface as the dense term's is (`gate`, widened for the
/// grids' noise) and faces t's camera. Both directions of an edge are summed.
/// Weighting (maximum likelihood beside the point-to-plane term, whose residuals are metres with
/// the reference spread NoiseScale::referenceSpread() at scale 1): each residual weighs
///   (reference spread x NoiseScale::between(s, t) / sigma)^2 x DensePointToPlane::sampleWeight(s),
/// so brightness counts more where depth is noisier, and the term integrates over the surface at
/// any grid step. Texture constrains what depth cannot: the turn of a surface of revolution.
struct DensePhotometric {
  static constexpr bool kReadsImages = true;  ///< keyframes need their IntensityImage (Energy::readsImages)
  SurfaceGate gate;  ///< the dense term's association gate (2 cm / 45 degrees)
  /// Intensity (0-1): the spread of one residual as the term weighs it. Far above a pixel's noise
  /// (~0.01): neighbouring residuals share the smoothing and the texture's sampling, and what the
  /// local mean leaves of the shading is a model error that no noise figure describes. Chosen on
  /// the stress matrix (0.015 to 0.6 tried): with less the textureless boxes at 2-3 m follow
  /// their shading (ADD-S 95.2 -> 92.7 at 0.25), with more the 2 m mug's twist is held less
  /// (mean rotation error 31 degrees at 0.4, 52 at 0.6, 91 without the term).
  double sigma = 0.4;
  /// Intensity: the Huber delta its energy uses by default (a brightness difference beyond it,
  /// an occlusion or a highlight, counts linearly).
  static constexpr double kHuberDelta = 0.1;

  struct Input {
    const SurfaceGrid& surface_i;
    const IntensityImage& image_i;
    const SurfaceGrid& surface_j;
    const IntensityImage& image_j;
  };
  static Input input(const EdgeView& edge) { return {edge.i.surface, edge.i.image, edge.j.surface, edge.j.image}; }

  template <RobustLoss Loss>
  void linearise(const Input& in, const SE3d& T_i, const SE3d& T_j, const Loss& loss, double weight,
                 PairSystem& system) const {
    if (weight == 0.0) return;
    const double noise = NoiseScale::referenceSpread() * NoiseScale::between(in.surface_i.noise_scale, in.surface_j.noise_scale) / sigma;
    weight *= noise * noise;
    addDirected(in.surface_i, in.image_i, in.surface_j, in.image_j, T_i, T_j, loss, weight, false, system);
    addDirected(in.surface_j, in.image_j, in.surface_i, in.image_i, T_j, T_i, loss, weight, true, system);
    system.finish();
  }

 private:
  template <typename Loss>
  void addDirected(const SurfaceGrid& s, const IntensityImage& image_s, const SurfaceGrid& t, const IntensityImage& image_t,
                   const SE3d& T_s, const SE3d& T_t, const Loss& loss, double weight, bool swapped, PairSystem& system) const {
    if (image_s.empty() || image_t.empty()) return;
    weight *= DensePointToPlane::sampleWeight(s);
    const auto affine = [](const SE3d& T) { return Eigen::Isometry3d(T.matrix()); };
    const Eigen::Isometry3d T_s_inv = affine(T_s.inverse()), T_t_s = affine(T_t * T_s.inverse());
    const Eigen::Matrix3d R_t = T_t.rotation().matrix(), R_t_s = T_t_s.linear();
    const SurfaceGate::Bounds<double> bounds = gate.widened(NoiseScale::between(s.noise_scale, t.noise_scale)).bounds<double>();
    // t's full-resolution camera: its grid's camera scaled back by the grid step.
    const double fx = double(t.camera.fx) * t.step, fy = double(t.camera.fy) * t.step;
    const double cx = double(t.camera.cx) * t.step, cy = double(t.camera.cy) * t.step;
    for (const IntensityImage::CellIntensity& sampled : image_s.cells) {
      const cv::Point& cell = s.cells[std::size_t(sampled.cell)];
      const double brightness_s = sampled.intensity;
      const cv::Vec3f& ps = s.point(cell);
      const Eigen::Vector3d p_s(ps[0], ps[1], ps[2]), q = T_t_s * p_s;
      int u = 0, v = 0;
      if (!t.camera.pixelOf(q, u, v) || !t.inside(u, v)) continue;
      const cv::Vec3f& pt = t.point(u, v);
      if (pt[2] <= 0.0f || (Eigen::Vector3d(pt[0], pt[1], pt[2]) - q).squaredNorm() > bounds.max_squared_distance) continue;
      const cv::Vec3f& ns = s.normal(cell);
      const cv::Vec3f& nt = t.normal(u, v);
      const Eigen::Vector3d n_q = R_t_s * Eigen::Vector3d(ns[0], ns[1], ns[2]);
      if (n_q.dot(q) >= 0.0 || n_q.dot(Eigen::Vector3d(nt[0], nt[1], nt[2])) < bounds.cos_max_angle) continue;
      const double iz = 1.0 / q.z();
      double brightness_t = 0.0, d_u = 0.0, d_v = 0.0;
      if (!image_t.sample(fx * q.x() * iz + cx, fy * q.y() * iz + cy, brightness_t, d_u, d_v)) continue;
      const Eigen::Matrix<double, 1, 6> J_t = imageResidualJacobian(imageGradientAt(q, fx, fy, d_u, d_v), T_s_inv * p_s, R_t);
      // J_i is dr/dd_s = -J_t when s is the edge's first node, J_t when it is the second.
      system.addRelative(brightness_t - brightness_s, swapped ? J_t : Eigen::Matrix<double, 1, 6>(-J_t), loss, weight);
    }
  }
};

}  // namespace bundletrack
