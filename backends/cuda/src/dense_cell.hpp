#pragma once

// The per-cell body of the GPU dense point-to-plane kernel (paper eq. 3), host and device.

#include <cmath>

#include "bundletrack/core/macros.hpp"
#include "dense_device.hpp"

namespace bundletrack::cuda::detail {

BUNDLETRACK_HOST_DEVICE inline void applyRigid(const double* T, const double* p, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = T[4 * r] * p[0] + T[4 * r + 1] * p[1] + T[4 * r + 2] * p[2] + T[4 * r + 3];
}

BUNDLETRACK_HOST_DEVICE inline void rotate(const double* T, const double* n, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = T[4 * r] * n[0] + T[4 * r + 1] * n[1] + T[4 * r + 2] * n[2];
}

/// rho(s) and rho'(s) of bundletrack's losses (robust/losses.hpp), selected by LossParameters::Kind.
BUNDLETRACK_HOST_DEVICE inline void evaluateLoss(int kind, double c, double s, double* rho, double* d_rho) {
  switch (kind) {
    case 1:  // Huber
      if (s <= c * c) *rho = s, *d_rho = 1.0;
      else *rho = 2.0 * c * sqrt(s) - c * c, *d_rho = c / sqrt(s);
      return;
    case 2: {  // Cauchy
      const double q = 1.0 + s / (c * c);
      *rho = c * c * log(q), *d_rho = 1.0 / q;
      return;
    }
    case 3: {  // Tukey
      if (s > c * c) {
        *rho = c * c / 3.0, *d_rho = 0.0;
        return;
      }
      const double q = 1.0 - s / (c * c);
      *rho = c * c / 3.0 * (1.0 - q * q * q), *d_rho = q * q;
      return;
    }
    default: *rho = s, *d_rho = 1.0;
  }
}

/// Pixel of a projected coordinate, rounded half away from zero as std::lround on the CPU.
BUNDLETRACK_HOST_DEVICE inline int roundToPixel(double x) { return int(x < 0.0 ? -floor(0.5 - x) : floor(x + 0.5)); }

/// Adds to the kDenseSums `sums` what surface cell `cell` of grid s contributes through its
/// projective association with grid t (nothing when it has none or fails a gate): the residual,
/// Jacobian and robust weight of bundletrack::DensePointToPlane. Grids are row-major xyz triples, z = 0 empty.
BUNDLETRACK_HOST_DEVICE inline void addDenseCell(const float* s_points, const float* s_normals, int cell,
                                                 const float* t_points, const float* t_normals, int t_width,
                                                 int t_height, const DirectedPass& pass, double* sums) {
  const double p_s[3] = {s_points[3 * cell], s_points[3 * cell + 1], s_points[3 * cell + 2]};
  double in_t[3];
  applyRigid(pass.T_t_s, p_s, in_t);
  if (in_t[2] <= 0.0) return;
  const int u = roundToPixel(pass.fx * in_t[0] / in_t[2] + pass.cx);
  const int v = roundToPixel(pass.fy * in_t[1] / in_t[2] + pass.cy);
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
  double rho, d_rho;
  evaluateLoss(pass.loss_kind, pass.loss_parameter, r * r, &rho, &d_rho);
  const double w = pass.weight * d_rho;
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 6; ++col) sums[6 * row + col] += w * J[row] * J[col];
    sums[36 + row] += w * r * J[row];
  }
  sums[42] += pass.weight * rho;
  sums[43] += 1.0;
}

}  // namespace bundletrack::cuda::detail
