#include <algorithm>
#include <stdexcept>
#include <vector>

#include "dense_cell.hpp"
#include "device_memory.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 128;

/// A pass as the kernel reads it: the grids' device pointers and the pass parameters.
struct KernelPass {
  const float* s_points;
  const float* s_normals;
  const int* s_cells;
  int s_count;
  const float* t_points;
  const float* t_normals;
  int t_width, t_height;
  DirectedPass pass;
};

/// Block row y works on pass y, one thread per surface cell of its s; warp sums, then one atomic
/// add per warp and value into the pass's kDenseSums slots.
__global__ void denseKernel(const KernelPass* passes, double* sums) {
  const KernelPass& p = passes[blockIdx.y];
  if (int(blockIdx.x * blockDim.x) >= p.s_count) return;  // the whole block: s has fewer cells
  double local[kDenseSums] = {};
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < p.s_count)
    addDenseCell(p.s_points, p.s_normals, p.s_cells[k], p.t_points, p.t_normals, p.t_width, p.t_height, p.pass, local);
  double* out = sums + std::size_t(kDenseSums) * blockIdx.y;
  for (int i = 0; i < kDenseSums; ++i) {
    double value = local[i];
    for (int offset = 16; offset > 0; offset /= 2) value += __shfl_down_sync(0xffffffffu, value, offset);
    if ((threadIdx.x & 31) == 0 && value != 0.0) atomicAdd(out + i, value);
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

struct DeviceBatch {
  KernelPass* passes = nullptr;
  double* sums = nullptr;
  std::size_t pass_capacity = 0, sum_capacity = 0;
  std::vector<KernelPass> staging;

  ~DeviceBatch() {
    if (passes) cudaFree(passes);
    if (sums) cudaFree(sums);
  }
};

DeviceBatch* createBatch() { return new DeviceBatch; }
void releaseBatch(DeviceBatch* batch) { delete batch; }

void accumulateDense(DeviceBatch& batch, const BatchPass* passes, int count, double* out) {
  const std::size_t values = std::size_t(kDenseSums) * std::size_t(count);
  for (std::size_t i = 0; i < values; ++i) out[i] = 0.0;
  if (count <= 0) return;
  if (count > 65535) throw std::runtime_error("GPU dense term: more than 65535 passes in one batch");
  batch.staging.resize(std::size_t(count));
  int most_cells = 0;
  for (int e = 0; e < count; ++e) {
    const DeviceGrid& s = *passes[e].s;
    const DeviceGrid& t = *passes[e].t;
    batch.staging[std::size_t(e)] = {s.points, s.normals, s.cells, s.count, t.points, t.normals, t.width, t.height,
                                     passes[e].pass};
    most_cells = std::max(most_cells, s.count);
  }
  if (most_cells == 0) return;
  grow(batch.passes, batch.pass_capacity, std::size_t(count));
  grow(batch.sums, batch.sum_capacity, values);
  check(cudaMemcpy(batch.passes, batch.staging.data(), std::size_t(count) * sizeof(KernelPass), cudaMemcpyHostToDevice),
        "copy passes");
  check(cudaMemset(batch.sums, 0, values * sizeof(double)), "memset");
  const dim3 blocks(unsigned((most_cells + kThreads - 1) / kThreads), unsigned(count));
  denseKernel<<<blocks, kThreads>>>(batch.passes, batch.sums);
  check(cudaGetLastError(), "dense kernel launch");
  check(cudaMemcpy(out, batch.sums, values * sizeof(double), cudaMemcpyDeviceToHost), "copy dense sums");
}

}  // namespace bundletrack::cuda::detail
