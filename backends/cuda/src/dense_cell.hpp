#pragma once

// The per-cell body of the GPU dense point-to-plane kernel (paper eq. 3), host and device.

#include <cmath>

#include "bundletrack/core/pixel.hpp"
#include "dense_device.hpp"

namespace bundletrack::cuda::detail {

BUNDLETRACK_HOST_DEVICE inline void applyRigid(const double* T, const double* p, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = T[4 * r] * p[0] + T[4 * r + 1] * p[1] + T[4 * r + 2] * p[2] + T[4 * r + 3];
}

BUNDLETRACK_HOST_DEVICE inline void rotate(const double* T, const double* n, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = T[4 * r] * n[0] + T[4 * r + 1] * n[1] + T[4 * r + 2] * n[2];
}

/// Adds to the kDenseSums `sums` what surface cell `cell` of grid s contributes through its
/// projective association with grid t (nothing when it has none or fails a gate): the residual,
/// Jacobian and robust weight of bundletrack::DensePointToPlane. Grids are row-major xyz triples, z = 0 empty.
BUNDLETRACK_HOST_DEVICE inline void addDenseCell(const float* s_points, const float* s_normals, int cell,
                                                 const float* t_points, const float* t_normals, int t_width,
                                                 int t_height, const DirectedPass& pass, double* sums) {
  const double p_s[3] = {s_points[3 * cell], s_points[3 * cell + 1], s_points[3 * cell + 2]};
  double in_t[3];
  applyRigid(pass.T_t_s, p_s, in_t);
  int u = 0, v = 0;
  if (!projectToPixel(pass.fx, pass.fy, pass.cx, pass.cy, in_t[0], in_t[1], in_t[2], u, v)) return;
  u -= pass.origin_x, v -= pass.origin_y;  // the cell in t's stored box
  if (u < 0 || v < 0 || u >= t_width || v >= t_height) return;
  const int at = v * t_width + u;
  if (t_points[3 * at + 2] <= 0.0f) return;
  const double p_t[3] = {t_points[3 * at], t_points[3 * at + 1], t_points[3 * at + 2]};
  double back[3];
  applyRigid(pass.T_s_t, p_t, back);
  const double dx = back[0] - p_s[0], dy = back[1] - p_s[1], dz = back[2] - p_s[2];
  if (dx * dx + dy * dy + dz * dz > pass.max_sq) return;
  const double n_s[3] = {s_normals[3 * cell], s_normals[3 * cell + 1], s_normals[3 * cell + 2]};
  const double n_t[3] = {t_normals[3 * at], t_normals[3 * at + 1], t_normals[3 * at + 2]};
  double turned[3];
  rotate(pass.T_s_t, n_t, turned);
  if (turned[0] * n_s[0] + turned[1] * n_s[1] + turned[2] * n_s[2] < pass.cos_max) return;
  // r = m . (T_t^-1 p_t - T_s^-1 p_s), m = R_s^T n_s; dr/dd_s = [m^T, (b x m)^T], b = T_t^-1 p_t.
  double m[3], a[3], b[3];
  rotate(pass.T_s_inv, n_s, m);
  applyRigid(pass.T_s_inv, p_s, a);
  applyRigid(pass.T_t_inv, p_t, b);
  const double r = m[0] * (b[0] - a[0]) + m[1] * (b[1] - a[1]) + m[2] * (b[2] - a[2]);
  const double J[6] = {m[0], m[1], m[2], b[1] * m[2] - b[2] * m[1], b[2] * m[0] - b[0] * m[2], b[0] * m[1] - b[1] * m[0]};
  const LossValue loss = pass.loss.evaluate(r * r);
  const double w = pass.weight * loss.d_rho;
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 6; ++col) sums[6 * row + col] += w * J[row] * J[col];
    sums[36 + row] += w * r * J[row];
  }
  sums[42] += pass.weight * loss.rho;
  sums[43] += 1.0;
}

}  // namespace bundletrack::cuda::detail
