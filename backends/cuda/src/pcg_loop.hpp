#pragma once

// The block-Jacobi PCG loop of the GPU solver, written once for a team of threads: the kernel
// runs it with the threads of one block, the host tests with a team of one.

#include <cmath>

#include "bundletrack/core/macros.hpp"

namespace bundletrack::cuda::detail {

/// A team of one thread on the host: every sum is its own value.
struct SerialTeam {
  int rank() const { return 0; }
  int size() const { return 1; }
  float sum(float value) const { return value; }
  void sync() const {}
};

/// z = M^-1 r with M^-1 block diagonal (6x6 blocks, row-major); the team splits the rows.
template <typename Team>
BUNDLETRACK_HOST_DEVICE void precondition(const Team& team, const float* block_inverse, const float* r, float* z,
                                          int n) {
  for (int i = team.rank(); i < n; i += team.size()) {
    const int block = i / 6, row = i % 6;
    const float* m = block_inverse + 36 * block + 6 * row;
    float sum = 0.0f;
    for (int c = 0; c < 6; ++c) sum += m[c] * r[6 * block + c];
    z[i] = sum;
  }
  team.sync();
}

/// Solves H x = b (H n x n row-major) as bundletrack::PCG does, in float: stops after
/// max_iterations, when |r| <= tolerance |b|, or when p has no positive curvature. r, z, p, Hp are
/// n-float scratch vectors. Returns the iterations; *relative_residual = |r| / |b|.
template <typename Team>
BUNDLETRACK_HOST_DEVICE int pcgIterations(const Team& team, const float* H, const float* block_inverse, const float* b,
                                          float* x, float* r, float* z, float* p, float* Hp, int n, int max_iterations,
                                          float tolerance, float* relative_residual) {
  float bb = 0.0f;
  for (int i = team.rank(); i < n; i += team.size()) x[i] = 0.0f, r[i] = b[i], bb += b[i] * b[i];
  const float b_norm = sqrtf(team.sum(bb));
  precondition(team, block_inverse, r, z, n);
  float rz = 0.0f, rr = 0.0f;
  for (int i = team.rank(); i < n; i += team.size()) p[i] = z[i], rz += r[i] * z[i], rr += r[i] * r[i];
  rz = team.sum(rz);
  rr = team.sum(rr);
  int iteration = 0;
  while (iteration < max_iterations && b_norm > 0.0f && sqrtf(rr) > tolerance * b_norm) {
    float pHp = 0.0f;
    for (int i = team.rank(); i < n; i += team.size()) {
      float sum = 0.0f;
      for (int c = 0; c < n; ++c) sum += H[i * n + c] * p[c];
      Hp[i] = sum;
      pHp += p[i] * sum;
    }
    pHp = team.sum(pHp);
    if (!(pHp > 0.0f)) break;
    const float alpha = rz / pHp;
    for (int i = team.rank(); i < n; i += team.size()) x[i] += alpha * p[i], r[i] -= alpha * Hp[i];
    team.sync();
    precondition(team, block_inverse, r, z, n);
    float rz_next = 0.0f;
    rr = 0.0f;
    for (int i = team.rank(); i < n; i += team.size()) rz_next += r[i] * z[i], rr += r[i] * r[i];
    rz_next = team.sum(rz_next);
    rr = team.sum(rr);
    const float beta = rz_next / rz;
    for (int i = team.rank(); i < n; i += team.size()) p[i] = z[i] + beta * p[i];
    team.sync();
    rz = rz_next;
    ++iteration;
  }
  *relative_residual = b_norm > 0.0f ? sqrtf(rr) / b_norm : 0.0f;
  return iteration;
}

}  // namespace bundletrack::cuda::detail
