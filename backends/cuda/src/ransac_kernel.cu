#include <stdexcept>

#include "device_memory.hpp"
#include "ransac_body.hpp"
#include "ransac_device.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 128;

/// One thread per trial: its sample and fit.
__global__ void trialKernel(const float* pairs, int n, TrialParameters parameters, int first, int count, double* fits,
                            float* hypotheses, unsigned char* valid) {
  const int b = blockIdx.x * blockDim.x + threadIdx.x;
  if (b >= count) return;
  valid[b] = fitTrial(pairs, n, parameters.seed, std::uint64_t(first + b), parameters.min_sample_spread, fits + 12 * b,
                      hypotheses + 12 * b)
                 ? 1
                 : 0;
}

/// One block per trial: its threads test the pairs in strides and sum their counts; every count
/// has its own slot, so blocks never race for the best hypothesis.
__global__ void countKernel(const float* pairs, int n, const float* hypotheses, const unsigned char* valid,
                            float max_squared_distance, float cos_max_angle, int* counts) {
  __shared__ int partial[kThreads];
  const int h = blockIdx.x;
  int inliers = 0;
  if (valid[h]) {
    const float* T = hypotheses + 12 * h;
    for (int k = threadIdx.x; k < n; k += blockDim.x)
      inliers += isInlier(T, pairs + 12 * k, max_squared_distance, cos_max_angle);
  }
  partial[threadIdx.x] = inliers;
  __syncthreads();
  for (int stride = blockDim.x / 2; stride > 0; stride /= 2) {
    if (threadIdx.x < stride) partial[threadIdx.x] += partial[threadIdx.x + stride];
    __syncthreads();
  }
  if (threadIdx.x == 0) counts[h] = partial[0];
}

}  // namespace

struct RansacBuffers {
  float* pairs = nullptr;
  double* fits = nullptr;
  float* hypotheses = nullptr;
  unsigned char* valid = nullptr;
  int* counts = nullptr;
  std::size_t pair_floats = 0, fit_doubles = 0, hypothesis_floats = 0, valid_bytes = 0, count_ints = 0;
  int n = 0;

  ~RansacBuffers() {
    for (void* p : {static_cast<void*>(pairs), static_cast<void*>(fits), static_cast<void*>(hypotheses),
                    static_cast<void*>(valid), static_cast<void*>(counts)})
      if (p) cudaFree(p);
  }
};

RansacBuffers* createRansacBuffers() { return new RansacBuffers; }
void destroyRansacBuffers(RansacBuffers* buffers) { delete buffers; }

void uploadPairs(RansacBuffers& b, const float* pairs, int n) {
  grow(b.pairs, b.pair_floats, std::size_t(12 * n));
  if (n > 0) check(cudaMemcpy(b.pairs, pairs, std::size_t(12 * n) * sizeof(float), cudaMemcpyHostToDevice), "copy pairs");
  b.n = n;
}

void scoreTrials(RansacBuffers& b, const TrialParameters& parameters, int first, int count, double* fits,
                 unsigned char* valid, int* counts) {
  if (count <= 0) return;
  if (b.n < 3) throw std::logic_error("GPU RANSAC: trials need at least 3 uploaded pairs");
  grow(b.fits, b.fit_doubles, std::size_t(12 * count));
  grow(b.hypotheses, b.hypothesis_floats, std::size_t(12 * count));
  grow(b.valid, b.valid_bytes, std::size_t(count));
  grow(b.counts, b.count_ints, std::size_t(count));
  trialKernel<<<(count + kThreads - 1) / kThreads, kThreads>>>(b.pairs, b.n, parameters, first, count, b.fits,
                                                               b.hypotheses, b.valid);
  check(cudaGetLastError(), "trial kernel launch");
  countKernel<<<count, kThreads>>>(b.pairs, b.n, b.hypotheses, b.valid, parameters.max_squared_distance,
                                   parameters.cos_max_angle, b.counts);
  check(cudaGetLastError(), "inlier kernel launch");
  check(cudaMemcpy(fits, b.fits, std::size_t(12 * count) * sizeof(double), cudaMemcpyDeviceToHost), "copy fits");
  check(cudaMemcpy(valid, b.valid, std::size_t(count), cudaMemcpyDeviceToHost), "copy validity");
  check(cudaMemcpy(counts, b.counts, std::size_t(count) * sizeof(int), cudaMemcpyDeviceToHost), "copy counts");
}

}  // namespace bundletrack::cuda::detail
