#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

#include "dense_device.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 128;
constexpr int kSums = 36 + 6 + 1 + 1;  ///< JtWJ, JtWr, cost, count

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA ") + what + ": " + cudaGetErrorString(status));
}

__device__ void apply(const double* T, const double* p, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = T[4 * r] * p[0] + T[4 * r + 1] * p[1] + T[4 * r + 2] * p[2] + T[4 * r + 3];
}

__device__ void rotate(const double* T, const double* n, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = T[4 * r] * n[0] + T[4 * r + 1] * n[1] + T[4 * r + 2] * n[2];
}

/// rho(s) and rho'(s) of bundletrack's losses (robust/losses.hpp).
__device__ void evaluateLoss(int kind, double c, double s, double* rho, double* d_rho) {
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

/// One thread per surface cell of s; warp sums, then one atomic add per warp and value.
__global__ void denseKernel(const float* s_points, const float* s_normals, const int* s_cells, int count,
                            const float* t_points, const float* t_normals, int t_width, int t_height, DirectedPass pass,
                            double* sums) {
  double local[kSums] = {};
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < count) {
    const int cell = s_cells[k];
    const double p_s[3] = {s_points[3 * cell], s_points[3 * cell + 1], s_points[3 * cell + 2]};
    double in_t[3];
    apply(pass.T_t_s, p_s, in_t);
    bool associated = in_t[2] > 0.0;
    int u = 0, v = 0;
    if (associated) {
      u = __double2int_rn(pass.fx * in_t[0] / in_t[2] + pass.cx);
      v = __double2int_rn(pass.fy * in_t[1] / in_t[2] + pass.cy);
      associated = u >= 0 && v >= 0 && u < t_width && v < t_height;
    }
    const int at = v * t_width + u;
    if (associated) associated = t_points[3 * at + 2] > 0.0f;
    if (associated) {
      const double p_t[3] = {t_points[3 * at], t_points[3 * at + 1], t_points[3 * at + 2]};
      double back[3];
      apply(pass.T_s_t, p_t, back);
      const double dx = back[0] - p_s[0], dy = back[1] - p_s[1], dz = back[2] - p_s[2];
      const double n_s[3] = {s_normals[3 * cell], s_normals[3 * cell + 1], s_normals[3 * cell + 2]};
      const double n_t[3] = {t_normals[3 * at], t_normals[3 * at + 1], t_normals[3 * at + 2]};
      double turned[3];
      rotate(pass.T_s_t, n_t, turned);
      if (dx * dx + dy * dy + dz * dz <= pass.max_sq &&
          turned[0] * n_s[0] + turned[1] * n_s[1] + turned[2] * n_s[2] >= pass.cos_max) {
        double m[3], a[3], b[3];
        rotate(pass.T_s_inv, n_s, m);
        apply(pass.T_s_inv, p_s, a);
        apply(pass.T_t_inv, p_t, b);
        const double r = m[0] * (b[0] - a[0]) + m[1] * (b[1] - a[1]) + m[2] * (b[2] - a[2]);
        const double J[6] = {m[0], m[1], m[2], b[1] * m[2] - b[2] * m[1], b[2] * m[0] - b[0] * m[2],
                             b[0] * m[1] - b[1] * m[0]};
        double rho, d_rho;
        evaluateLoss(pass.loss_kind, pass.loss_parameter, r * r, &rho, &d_rho);
        const double w = pass.weight * d_rho;
        for (int row = 0; row < 6; ++row) {
          for (int col = 0; col < 6; ++col) local[6 * row + col] = w * J[row] * J[col];
          local[36 + row] = w * r * J[row];
        }
        local[42] = pass.weight * rho;
        local[43] = 1.0;
      }
    }
  }
  for (int i = 0; i < kSums; ++i) {
    double value = local[i];
    for (int offset = 16; offset > 0; offset /= 2) value += __shfl_down_sync(0xffffffffu, value, offset);
    if ((threadIdx.x & 31) == 0 && value != 0.0) atomicAdd(sums + i, value);
  }
}

}  // namespace

struct DeviceGrid {
  float* points = nullptr;
  float* normals = nullptr;
  int* cells = nullptr;
  int width = 0, height = 0, count = 0;

  ~DeviceGrid() {
    for (void* p : {static_cast<void*>(points), static_cast<void*>(normals), static_cast<void*>(cells)})
      if (p) cudaFree(p);
  }
};

DeviceGrid* uploadGrid(const float* points, const float* normals, int width, int height, const int* cells, int count) {
  auto* grid = new DeviceGrid;
  try {
    grid->width = width, grid->height = height, grid->count = count;
    const std::size_t floats = std::size_t(width) * std::size_t(height) * 3;
    check(cudaMalloc(&grid->points, floats * sizeof(float)), "malloc");
    check(cudaMalloc(&grid->normals, floats * sizeof(float)), "malloc");
    check(cudaMalloc(&grid->cells, std::size_t(count > 0 ? count : 1) * sizeof(int)), "malloc");
    check(cudaMemcpy(grid->points, points, floats * sizeof(float), cudaMemcpyHostToDevice), "copy grid points");
    check(cudaMemcpy(grid->normals, normals, floats * sizeof(float), cudaMemcpyHostToDevice), "copy grid normals");
    if (count > 0) check(cudaMemcpy(grid->cells, cells, std::size_t(count) * sizeof(int), cudaMemcpyHostToDevice), "copy cells");
  } catch (...) {
    delete grid;
    throw;
  }
  return grid;
}

void releaseGrid(DeviceGrid* grid) { delete grid; }

struct DeviceSums {
  double* values = nullptr;
  DeviceSums() { check(cudaMalloc(&values, kSums * sizeof(double)), "malloc"); }
  ~DeviceSums() { cudaFree(values); }
};

DeviceSums* createSums() { return new DeviceSums; }
void releaseSums(DeviceSums* sums) { delete sums; }

void accumulateDense(DeviceSums& sums, const DeviceGrid& s, const DeviceGrid& t, const DirectedPass& pass,
                     double JtWJ[36], double JtWr[6], double* cost, int* count) {
  double host[kSums] = {};
  if (s.count > 0) {
    check(cudaMemset(sums.values, 0, kSums * sizeof(double)), "memset");
    denseKernel<<<(s.count + kThreads - 1) / kThreads, kThreads>>>(s.points, s.normals, s.cells, s.count, t.points,
                                                                   t.normals, t.width, t.height, pass, sums.values);
    check(cudaGetLastError(), "dense kernel launch");
    check(cudaMemcpy(host, sums.values, kSums * sizeof(double), cudaMemcpyDeviceToHost), "copy dense sums");
  }
  for (int i = 0; i < 36; ++i) JtWJ[i] = host[i];
  for (int i = 0; i < 6; ++i) JtWr[i] = host[36 + i];
  *cost = host[42];
  *count = int(host[43] + 0.5);
}

}  // namespace bundletrack::cuda::detail
