#pragma once

#include <cmath>

#include <Eigen/Geometry>

#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/core/pixel.hpp"
#include "bundletrack/core/silhouette_image.hpp"
#include "bundletrack/residuals/image_jacobian.hpp"
#include "bundletrack/residuals/residual.hpp"

namespace bundletrack {

/// Beyond the paper: every point of the object projects inside the object's silhouette in every
/// view, seen or hidden (docs/DESIGN.md section 7). A point p_s of frame s (a mask pixel with
/// depth, every grid step, that is the object's: makeSilhouetteImage) is the object point
/// a = T_s^-1 p_s; seen from frame t at q = T_t a it
/// should not land outside t's mask:
///   r = max(0, D_t(pi(q))),
/// D_t the signed distance to t's outline in pixels (positive outside), with the Jacobian of an
/// image residual (imageResidualJacobian) where r > 0, and dr/dd_s = -dr/dd_t. It counts only
/// where t saw past the point: t's reading there farther than it by more than three standard
/// deviations of two readings' difference. A nearer reading may be an occluder that the mask
/// leaves out (a hand, a support it stands on or in), one within the noise of the point the
/// object itself where t's mask misses it (a segmentation's rim, a mask moved by the depth-to-colour
/// registration). Without a reading nothing says the object is not there (a dropout, a shadow, a
/// rim the depth filter took off, a depth camera's narrower view), unless SilhouetteImage::depth
/// says t saw past it: a given mask's background with no reading within a few pixels, beyond the
/// sensor's range. Nor does a point that lands outside t's silhouette image count.
/// Both directions of an edge are summed. The masks must end at the object's outline where they
/// end before a farther surface (kOutline: given masks, and propagated ones, which end
/// there at the depth edge).
/// What it holds: the outline pins the motion that the surface lets slide -- a box seen on two
/// faces slides along their common edge, a plane in its own plane -- where there is no texture.
/// Weighting (maximum likelihood beside the point-to-plane term, as the photometric term): each
/// residual weighs (reference spread x NoiseScale::between(s, t))^2 / (sigma^2 + e^2) x step / 4,
/// where sigma is the outline's spread and e how far p_s's depth error (s's spread) moves it
/// across t's outline (none when t looks along s's ray, most for views far apart), and step / 4
/// makes the outline, a line of samples, the same line integral at any grid step.
struct DenseSilhouette {
  static constexpr bool kReadsSilhouettes = true;  ///< keyframes need their SilhouetteImage (Energy::readsSilhouettes)
  /// Pixels: the spread of the mask's outline. A rendered mask is exact to the pixel, but a real
  /// one is not: colour and depth are registered to 1-3 px at edges, and a segmentation's boundary
  /// errs by as much. With masks jittered by 1-2 px per frame, 1 px turned a 1 m mug by 13-42
  /// degrees (2.6-5.0 without the term), 2 px by 8-9.
  double sigma = 2.0;
  /// Pixels: the Huber delta its energy uses by default (a point farther out, where the mask
  /// misses part of the object, counts linearly).
  static constexpr double kHuberDelta = 1.0;

  struct Input {
    const SurfaceGrid& surface_i;
    const SilhouetteImage& silhouette_i;
    const SurfaceGrid& surface_j;
    const SilhouetteImage& silhouette_j;
  };
  static Input input(const EdgeView& edge) {
    return {edge.i.surface, edge.i.silhouette, edge.j.surface, edge.j.silhouette};
  }

  template <RobustLoss Loss>
  void linearise(const Input& in, const SE3d& T_i, const SE3d& T_j, const Loss& loss, double weight,
                 PairSystem& system) const {
    if (weight == 0.0) return;
    const double scale = NoiseScale::between(in.surface_i.noise_scale, in.surface_j.noise_scale);
    const double depth_noise = NoiseScale::referenceSpread() * scale;
    weight *= depth_noise * depth_noise;
    // Three standard deviations of the difference of two readings.
    const double occlusion_margin = 3.0 * std::sqrt(2.0) * depth_noise;
    addDirected(in.surface_i, in.silhouette_i, in.surface_j, in.silhouette_j, T_i, T_j, loss, weight, occlusion_margin, false,
                system);
    addDirected(in.surface_j, in.silhouette_j, in.surface_i, in.silhouette_i, T_j, T_i, loss, weight, occlusion_margin, true,
                system);
    system.finish();
  }

 private:
  template <typename Loss>
  void addDirected(const SurfaceGrid& s_grid, const SilhouetteImage& s, const SurfaceGrid& t_grid, const SilhouetteImage& t,
                   const SE3d& T_s, const SE3d& T_t, const Loss& loss, double weight, double occlusion_margin,
                   bool swapped, PairSystem& system) const {
    if (s.empty() || t.empty()) return;
    weight *= s_grid.step / 4.0;
    const double depth_spread = NoiseScale::referenceSpread() * s_grid.noise_scale;  // of s's readings
    const auto affine = [](const SE3d& T) { return Eigen::Isometry3d(T.matrix()); };
    const Eigen::Isometry3d T_s_inv = affine(T_s.inverse()), T_t_s = affine(T_t * T_s.inverse());
    const Eigen::Matrix3d R_t = T_t.rotation().matrix(), R_t_s = T_t_s.linear();
    // t's full-resolution camera: its grid's camera scaled back by the grid step.
    const double fx = double(t_grid.camera.fx) * t_grid.step, fy = double(t_grid.camera.fy) * t_grid.step;
    const double cx = double(t_grid.camera.cx) * t_grid.step, cy = double(t_grid.camera.cy) * t_grid.step;
    for (const cv::Vec3f& ps : s.points) {
      const Eigen::Vector3d p_s(ps[0], ps[1], ps[2]), q = T_t_s * p_s;
      if (q.z() <= 0.0) continue;
      const double u = fx * q.x() / q.z() + cx, v = fy * q.y() / q.z() + cy;
      double distance = 0.0, d_u = 0.0, d_v = 0.0;
      if (t.deepInside(u, v) || !t.sample(u, v, distance, d_u, d_v) || distance <= 0.0) continue;
      // t must have seen past the point there: a nearer reading may be an occluder, one as near the
      // object where t's mask misses it; where nothing is known (0) nothing says the object is not there.
      const float seen = t.depthAt(roundToPixel(u), roundToPixel(v));
      if (seen <= 0.0f || seen <= q.z() + occlusion_margin) continue;
      const Eigen::Vector3d g = imageGradientAt(q, fx, fy, d_u, d_v);
      // The point's depth error moves it along s's ray, and so across t's outline by g . R_t_s p_s / z_s
      // pixels per metre: the residual's spread beside the outline's own.
      const double across = g.dot(R_t_s * p_s) / p_s.z() * depth_spread;
      const Eigen::Matrix<double, 1, 6> J_t = imageResidualJacobian(g, T_s_inv * p_s, R_t);
      // J_i is dr/dd_s = -J_t when s is the edge's first node, J_t when it is the second.
      system.addRelative(distance, swapped ? J_t : Eigen::Matrix<double, 1, 6>(-J_t), loss,
                         weight / (sigma * sigma + across * across));
    }
  }
};

}  // namespace bundletrack
