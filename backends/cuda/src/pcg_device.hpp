#pragma once

// The boundary between host code and the CUDA translation unit: plain pointers and integers only.

namespace bundletrack::cuda::detail {

/// Device buffers of one solver, grown on demand (owned by the .cu side).
struct DeviceBuffers;

DeviceBuffers* createBuffers();
void destroyBuffers(DeviceBuffers* buffers);

/// Solves H x = rhs by block-Jacobi PCG on the device. H is n x n row-major, block_inverse holds
/// n / 6 row-major 6x6 preconditioner blocks; host arrays in, x out. Returns the iterations and
/// writes the final relative residual.
int solvePcg(DeviceBuffers& buffers, const float* H, const float* block_inverse, const float* rhs, float* x, int n,
             int max_iterations, float tolerance, float* relative_residual);

bool deviceAvailable();

}  // namespace bundletrack::cuda::detail
