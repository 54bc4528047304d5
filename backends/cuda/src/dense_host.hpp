#pragma once

// What the host hands the dense kernel: a directed pass's parameters and a keyframe's surface
// cells, in the plain layout of dense_device.hpp.

#include <vector>

#include "bundletrack/cuda/dense_point_to_plane.hpp"
#include "dense_device.hpp"

namespace bundletrack::cuda::detail {

inline void rowMajor3x4(const SE3d& T, double out[12]) {
  const Eigen::Matrix4d M = T.matrix();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = M(r, c);
}

/// The pass s -> t of an edge whose nodes have poses T_s, T_t (object in camera), with the gate of
/// DensePointToPlane and t's grid camera and origin.
inline DirectedPass directedPass(const SE3d& T_s, const SE3d& T_t, const SurfaceGrid& t, const SurfaceGate& gate,
                                 const LossParameters& loss, double weight) {
  DirectedPass p{};
  rowMajor3x4(T_t * T_s.inverse(), p.T_t_s);
  rowMajor3x4(T_s * T_t.inverse(), p.T_s_t);
  rowMajor3x4(T_s.inverse(), p.T_s_inv);
  rowMajor3x4(T_t.inverse(), p.T_t_inv);
  const SurfaceGate::Bounds<double> bounds = gate.bounds<double>();
  p.cos_max = bounds.cos_max_angle;
  p.max_sq = bounds.max_squared_distance;
  p.fx = t.camera.fx, p.fy = t.camera.fy, p.cx = t.camera.cx, p.cy = t.camera.cy;
  p.origin_x = t.origin.x, p.origin_y = t.origin.y;
  p.loss = loss;
  p.weight = weight;
  return p;
}

/// Adds a pass's sums to the edge's system: J_i is J_s, or -J_s when s is the edge's second node
/// (`swapped`), so J^T J keeps its sign and J^T r flips.
inline void addPassSums(const double sums[kDenseSums], bool swapped, PairSystem& system) {
  const Eigen::Matrix<double, 6, 1> b = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(sums + 36);
  system.addRelativeSums(Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(sums), swapped ? -b : b,
                         sums[42], int(sums[43] + 0.5));
}

/// Row-major indices of a grid's surface cells in its stored box.
inline std::vector<int> surfaceCells(const SurfaceGrid& grid) {
  std::vector<int> cells(grid.cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const cv::Point local = grid.cells[i] - grid.origin;
    cells[i] = local.y * grid.points.cols + local.x;
  }
  return cells;
}

}  // namespace bundletrack::cuda::detail
