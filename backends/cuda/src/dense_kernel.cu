#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

#include "dense_cell.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 128;

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA ") + what + ": " + cudaGetErrorString(status));
}

/// One thread per surface cell of s; warp sums, then one atomic add per warp and value.
__global__ void denseKernel(const float* s_points, const float* s_normals, const int* s_cells, int count,
                            const float* t_points, const float* t_normals, int t_width, int t_height, DirectedPass pass,
                            double* sums) {
  double local[kDenseSums] = {};
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < count) addDenseCell(s_points, s_normals, s_cells[k], t_points, t_normals, t_width, t_height, pass, local);
  for (int i = 0; i < kDenseSums; ++i) {
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
  DeviceSums() { check(cudaMalloc(&values, kDenseSums * sizeof(double)), "malloc"); }
  ~DeviceSums() { cudaFree(values); }
};

DeviceSums* createSums() { return new DeviceSums; }
void releaseSums(DeviceSums* sums) { delete sums; }

void accumulateDense(DeviceSums& sums, const DeviceGrid& s, const DeviceGrid& t, const DirectedPass& pass,
                     double out[kDenseSums]) {
  for (int i = 0; i < kDenseSums; ++i) out[i] = 0.0;
  if (s.count == 0) return;
  check(cudaMemset(sums.values, 0, kDenseSums * sizeof(double)), "memset");
  denseKernel<<<(s.count + kThreads - 1) / kThreads, kThreads>>>(s.points, s.normals, s.cells, s.count, t.points,
                                                                 t.normals, t.width, t.height, pass, sums.values);
  check(cudaGetLastError(), "dense kernel launch");
  check(cudaMemcpy(out, sums.values, kDenseSums * sizeof(double), cudaMemcpyDeviceToHost), "copy dense sums");
}

}  // namespace bundletrack::cuda::detail
