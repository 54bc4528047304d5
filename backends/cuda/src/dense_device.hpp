#pragma once

// The boundary between host code and the CUDA translation unit: plain data and pointers only.

#include "bundletrack/robust/loss_kind.hpp"

namespace bundletrack::cuda::detail {

/// A keyframe's dense grid on the device (owned by the .cu side).
struct DeviceGrid;

/// Copies a grid of width x height points and normals (3 floats each, row-major) and the list of
/// its surface cells (row-major cell indices) to the device.
DeviceGrid* uploadGrid(const float* points, const float* normals, int width, int height, const int* cells, int count);
void releaseGrid(DeviceGrid* grid);

/// One direction s -> t of an edge: rigid maps as row-major 3x4 [R | t] in double, the gates and
/// the grid camera with the grid cell of t's first stored point, and the robust loss.
struct DirectedPass {
  double T_t_s[12], T_s_t[12], T_s_inv[12], T_t_inv[12];
  double cos_max, max_sq;
  float fx, fy, cx, cy;  ///< t's grid camera
  int origin_x, origin_y;  ///< t's SurfaceGrid::origin
  LossParameters loss;
  double weight;
};

/// The sums of a pass over its cells: w J^T J (36, row-major), w r J (6), the weighted losses and
/// the count, with J = dr/dd_s (DensePointToPlane's documentation).
constexpr int kDenseSums = 36 + 6 + 1 + 1;

/// A pass of a batch: the cells of grid s associated with grid t.
struct BatchPass {
  const DeviceGrid* s;
  const DeviceGrid* t;
  DirectedPass pass;
};

/// Device memory of one caller's batches, grown on demand (owned by the .cu side).
struct DeviceBatch;
DeviceBatch* createBatch();
void releaseBatch(DeviceBatch* batch);

/// The sums of `count` passes in one launch, copied to `out` (count x kDenseSums) on the host.
void accumulateDense(DeviceBatch& batch, const BatchPass* passes, int count, double* out);

}  // namespace bundletrack::cuda::detail
