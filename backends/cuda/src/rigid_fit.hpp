#pragma once

// The least-squares rigid fit of three point pairs, host and device (RANSAC's hypotheses).

#include <cmath>

#include "bundletrack/core/macros.hpp"

namespace bundletrack::cuda::detail {

/// Eigen-decomposes the symmetric 4x4 matrix A by cyclic Jacobi rotations (A is destroyed; its
/// diagonal ends up holding the eigenvalues) and returns the eigenvector of the largest one.
BUNDLETRACK_HOST_DEVICE inline void largestEigenvector4(double A[4][4], double out[4]) {
  double V[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  for (int sweep = 0; sweep < 50; ++sweep) {
    double off = 0.0, scale = 0.0;
    for (int p = 0; p < 4; ++p) {
      scale += A[p][p] * A[p][p];
      for (int q = p + 1; q < 4; ++q) off += A[p][q] * A[p][q];
    }
    if (off <= 1e-32 * scale || off == 0.0) break;
    for (int p = 0; p < 3; ++p) {
      for (int q = p + 1; q < 4; ++q) {
        const double apq = A[p][q];
        if (apq == 0.0) continue;
        // The rotation in the (p, q) plane that zeroes A[p][q] (Numerical Recipes' form).
        const double theta = (A[q][q] - A[p][p]) / (2.0 * apq);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
        const double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 4; ++k) {
          const double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - s * akq, A[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 4; ++k) {
          const double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - s * aqk, A[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 4; ++k) {
          const double vkp = V[k][p], vkq = V[k][q];
          V[k][p] = c * vkp - s * vkq, V[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int largest = 0;
  for (int k = 1; k < 4; ++k)
    if (A[k][k] > A[largest][largest]) largest = k;
  for (int k = 0; k < 4; ++k) out[k] = V[k][largest];
}

/// T (row-major 3x4 [R | t]) minimising sum_k |T a_k - b_k|^2 over three pairs, by Horn's closed
/// form (J. Opt. Soc. Am. A 4(4), 1987): the rotation is the unit quaternion that maximises
/// q^T N q, N the 4x4 symmetric matrix of the pairs' cross-covariance. The same optimum as
/// bundletrack::kabsch (always a proper rotation).
BUNDLETRACK_HOST_DEVICE inline void fitRigid3(const float* const a[3], const float* const b[3], double T[12]) {
  double mean_a[3] = {0, 0, 0}, mean_b[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i) mean_a[i] += a[k][i] / 3.0, mean_b[i] += b[k][i] / 3.0;
  double S[3][3] = {};  // S[i][j] = sum_k (a_k - mean_a)_i (b_k - mean_b)_j
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) S[i][j] += (a[k][i] - mean_a[i]) * (b[k][j] - mean_b[j]);
  double N[4][4] = {
      {S[0][0] + S[1][1] + S[2][2], S[1][2] - S[2][1], S[2][0] - S[0][2], S[0][1] - S[1][0]},
      {S[1][2] - S[2][1], S[0][0] - S[1][1] - S[2][2], S[0][1] + S[1][0], S[2][0] + S[0][2]},
      {S[2][0] - S[0][2], S[0][1] + S[1][0], -S[0][0] + S[1][1] - S[2][2], S[1][2] + S[2][1]},
      {S[0][1] - S[1][0], S[2][0] + S[0][2], S[1][2] + S[2][1], -S[0][0] - S[1][1] + S[2][2]}};
  double q[4];
  largestEigenvector4(N, q);
  const double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double w = q[0] / norm, x = q[1] / norm, y = q[2] / norm, z = q[3] / norm;
  const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T[4 * r + c] = R[r][c];
    T[4 * r + 3] = mean_b[r] - (R[r][0] * mean_a[0] + R[r][1] * mean_a[1] + R[r][2] * mean_a[2]);
  }
}

}  // namespace bundletrack::cuda::detail
