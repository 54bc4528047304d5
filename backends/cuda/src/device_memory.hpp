#pragma once

// CUDA error checks and growable device buffers, shared by the kernels' translation units.

#include <cuda_runtime.h>

#include <cstddef>
#include <stdexcept>
#include <string>

namespace bundletrack::cuda::detail {

/// Throws std::runtime_error naming `what` when a CUDA call failed.
inline void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA ") + what + ": " + cudaGetErrorString(status));
}

/// Makes `buffer` hold at least `count` elements (its contents are not kept when it grows).
template <typename T>
void grow(T*& buffer, std::size_t& capacity, std::size_t count) {
  if (count <= capacity) return;
  if (buffer) check(cudaFree(buffer), "free");
  buffer = nullptr;
  capacity = 0;
  check(cudaMalloc(&buffer, count * sizeof(T)), "malloc");
  capacity = count;
}

}  // namespace bundletrack::cuda::detail
