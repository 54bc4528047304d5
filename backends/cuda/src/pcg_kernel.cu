#include "device_memory.hpp"
#include "pcg_device.hpp"
#include "pcg_loop.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 256;

/// The threads of one block; sum() leaves the total with every thread.
struct BlockTeam {
  float* scratch;  ///< kThreads floats of shared memory

  __device__ int rank() const { return threadIdx.x; }
  __device__ int size() const { return blockDim.x; }
  __device__ void sync() const { __syncthreads(); }
  __device__ float sum(float value) const {
    scratch[threadIdx.x] = value;
    __syncthreads();
    for (int stride = blockDim.x / 2; stride > 0; stride /= 2) {
      if (threadIdx.x < stride) scratch[threadIdx.x] += scratch[threadIdx.x + stride];
      __syncthreads();
    }
    const float total = scratch[0];
    __syncthreads();
    return total;
  }
};

/// The whole PCG loop in one block: the systems are small (6 unknowns per keyframe), so one launch
/// and block-wide reductions beat a launch per vector operation.
__global__ void pcgKernel(const float* H, const float* block_inverse, const float* b, float* x, float* r, float* z,
                          float* p, float* Hp, int n, int max_iterations, float tolerance, int* iterations_out,
                          float* residual_out) {
  __shared__ float scratch[kThreads];
  float residual = 0.0f;
  const int iterations = pcgIterations(BlockTeam{scratch}, H, block_inverse, b, x, r, z, p, Hp, n, max_iterations,
                                       tolerance, &residual);
  if (threadIdx.x == 0) *iterations_out = iterations, *residual_out = residual;
}

}  // namespace

struct DeviceBuffers {
  int capacity = 0;  // unknowns the buffers hold
  float *H = nullptr, *block_inverse = nullptr, *b = nullptr, *x = nullptr, *r = nullptr, *z = nullptr, *p = nullptr,
        *Hp = nullptr, *residual = nullptr;
  int* iterations = nullptr;

  void release() {
    for (float* buffer : {H, block_inverse, b, x, r, z, p, Hp, residual}) cudaFree(buffer);
    cudaFree(iterations);
    H = block_inverse = b = x = r = z = p = Hp = residual = nullptr;
    iterations = nullptr;
    capacity = 0;
  }

  void reserve(int n) {
    if (n <= capacity) return;
    release();
    const std::size_t vector = sizeof(float) * std::size_t(n);
    check(cudaMalloc(&H, vector * std::size_t(n)), "cudaMalloc");
    check(cudaMalloc(&block_inverse, vector * 6), "cudaMalloc");
    for (float** buffer : {&b, &x, &r, &z, &p, &Hp}) check(cudaMalloc(buffer, vector), "cudaMalloc");
    check(cudaMalloc(&residual, sizeof(float)), "cudaMalloc");
    check(cudaMalloc(&iterations, sizeof(int)), "cudaMalloc");
    capacity = n;
  }
};

DeviceBuffers* createBuffers() { return new DeviceBuffers(); }

void destroyBuffers(DeviceBuffers* buffers) {
  if (buffers) buffers->release();
  delete buffers;
}

int solvePcg(DeviceBuffers& d, const float* H, const float* block_inverse, const float* rhs, float* x, int n,
             int max_iterations, float tolerance, float* relative_residual) {
  d.reserve(n);
  const std::size_t vector = sizeof(float) * std::size_t(n);
  check(cudaMemcpy(d.H, H, vector * std::size_t(n), cudaMemcpyHostToDevice), "copy H");
  check(cudaMemcpy(d.block_inverse, block_inverse, vector * 6, cudaMemcpyHostToDevice), "copy preconditioner");
  check(cudaMemcpy(d.b, rhs, vector, cudaMemcpyHostToDevice), "copy rhs");
  pcgKernel<<<1, kThreads>>>(d.H, d.block_inverse, d.b, d.x, d.r, d.z, d.p, d.Hp, n, max_iterations, tolerance,
                             d.iterations, d.residual);
  check(cudaGetLastError(), "pcgKernel launch");
  int iterations = 0;
  check(cudaMemcpy(x, d.x, vector, cudaMemcpyDeviceToHost), "copy x");
  check(cudaMemcpy(&iterations, d.iterations, sizeof(int), cudaMemcpyDeviceToHost), "copy iterations");
  check(cudaMemcpy(relative_residual, d.residual, sizeof(float), cudaMemcpyDeviceToHost), "copy residual");
  return iterations;
}

bool deviceAvailable() {
  int count = 0;
  return cudaGetDeviceCount(&count) == cudaSuccess && count > 0;
}

}  // namespace bundletrack::cuda::detail
