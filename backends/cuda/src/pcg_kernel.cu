#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

#include "pcg_device.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 256;

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("CUDA ") + what + ": " + cudaGetErrorString(status));
}

/// Sum over the block of each thread's `value` (every thread gets the total).
__device__ float blockSum(float value, float* scratch) {
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

/// z = M^-1 r with M^-1 block diagonal (6x6 blocks, row-major).
__device__ void precondition(const float* block_inverse, const float* r, float* z, int n) {
  for (int i = threadIdx.x; i < n; i += blockDim.x) {
    const int block = i / 6, row = i % 6;
    const float* m = block_inverse + 36 * block + 6 * row;
    float sum = 0.0f;
    for (int c = 0; c < 6; ++c) sum += m[c] * r[6 * block + c];
    z[i] = sum;
  }
  __syncthreads();
}

/// The whole PCG loop in one block: the systems are small (6 unknowns per keyframe), so one launch
/// and block-wide reductions beat a launch per vector operation.
__global__ void pcgKernel(const float* H, const float* block_inverse, const float* b, float* x, float* r, float* z,
                          float* p, float* Hp, int n, int max_iterations, float tolerance, int* iterations_out,
                          float* residual_out) {
  __shared__ float scratch[kThreads];
  float bb = 0.0f;
  for (int i = threadIdx.x; i < n; i += blockDim.x) x[i] = 0.0f, r[i] = b[i], bb += b[i] * b[i];
  const float b_norm = sqrtf(blockSum(bb, scratch));
  precondition(block_inverse, r, z, n);
  float rz = 0.0f, rr = 0.0f;
  for (int i = threadIdx.x; i < n; i += blockDim.x) p[i] = z[i], rz += r[i] * z[i], rr += r[i] * r[i];
  rz = blockSum(rz, scratch);
  rr = blockSum(rr, scratch);
  int iteration = 0;
  while (iteration < max_iterations && b_norm > 0.0f && sqrtf(rr) > tolerance * b_norm) {
    float pHp = 0.0f;
    for (int i = threadIdx.x; i < n; i += blockDim.x) {
      float sum = 0.0f;
      for (int c = 0; c < n; ++c) sum += H[i * n + c] * p[c];
      Hp[i] = sum;
      pHp += p[i] * sum;
    }
    pHp = blockSum(pHp, scratch);
    if (!(pHp > 0.0f)) break;
    const float alpha = rz / pHp;
    for (int i = threadIdx.x; i < n; i += blockDim.x) x[i] += alpha * p[i], r[i] -= alpha * Hp[i];
    __syncthreads();
    precondition(block_inverse, r, z, n);
    float rz_next = 0.0f;
    rr = 0.0f;
    for (int i = threadIdx.x; i < n; i += blockDim.x) rz_next += r[i] * z[i], rr += r[i] * r[i];
    rz_next = blockSum(rz_next, scratch);
    rr = blockSum(rr, scratch);
    const float beta = rz_next / rz;
    for (int i = threadIdx.x; i < n; i += blockDim.x) p[i] = z[i] + beta * p[i];
    __syncthreads();
    rz = rz_next;
    ++iteration;
  }
  if (threadIdx.x == 0) *iterations_out = iteration, *residual_out = b_norm > 0.0f ? sqrtf(rr) / b_norm : 0.0f;
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
