#include <cmath>
#include <stdexcept>
#include <string>

#include "bundletrack/features/two_nearest.hpp"
#include "device_memory.hpp"
#include "matching_device.hpp"
#include "matching_metric.hpp"

namespace bundletrack::cuda::detail {

namespace {

constexpr int kThreads = 128;  ///< query rows per block
constexpr int kTile = 32;  ///< train rows staged in shared memory at a time
constexpr int kMaxSharedBytes = 48 * 1024;

/// One thread per query row; the block stages kTile train rows at a time in shared memory. Ties
/// go to the lower train index, as in the CPU matcher.
template <typename Word, typename Metric>
__global__ void twoNearestKernel(const Word* query, int queries, const Word* train, int trains, int width, int* index,
                                 float* best, float* second) {
  extern __shared__ unsigned char shared[];
  Word* tile = reinterpret_cast<Word*>(shared);
  const int q = blockIdx.x * blockDim.x + threadIdx.x;
  TwoNearest nearest;
  for (int start = 0; start < trains; start += kTile) {
    const int count = min(kTile, trains - start);
    for (int k = threadIdx.x; k < count * width; k += blockDim.x) tile[k] = train[start * width + k];
    __syncthreads();
    if (q < queries) {
      for (int t = 0; t < count; ++t) {
        const float d = Metric::distance(query + q * width, tile + t * width, width);
        nearest.offer(d, start + t);
      }
    }
    __syncthreads();
  }
  if (q < queries) index[q] = nearest.index, best[q] = nearest.best, second[q] = nearest.second;
}

}  // namespace

struct MatchBuffers {
  void* query = nullptr;
  void* train = nullptr;
  int* index = nullptr;
  float* best = nullptr;
  float* second = nullptr;
  std::size_t query_bytes = 0, train_bytes = 0, rows = 0, rows_best = 0, rows_second = 0;

  ~MatchBuffers() {
    for (void* p : {query, train, static_cast<void*>(index), static_cast<void*>(best), static_cast<void*>(second)})
      if (p) cudaFree(p);
  }
};

MatchBuffers* createMatchBuffers() { return new MatchBuffers; }
void destroyMatchBuffers(MatchBuffers* buffers) { delete buffers; }

namespace {

template <typename Word, typename Metric>
void twoNearest(MatchBuffers& m, const Word* query, int queries, const Word* train, int trains, int width, int* index,
                float* best, float* second) {
  if (queries <= 0) return;
  const std::size_t shared_bytes = std::size_t(kTile) * std::size_t(width) * sizeof(Word);
  if (shared_bytes > std::size_t(kMaxSharedBytes))
    throw std::runtime_error("GPU matcher: descriptors of " + std::to_string(width * sizeof(Word)) +
                             " bytes exceed the shared-memory tile (at most " +
                             std::to_string(kMaxSharedBytes / kTile) + " bytes)");
  const std::size_t query_bytes = std::size_t(queries) * std::size_t(width) * sizeof(Word);
  const std::size_t train_bytes = std::size_t(trains) * std::size_t(width) * sizeof(Word);
  unsigned char* q = static_cast<unsigned char*>(m.query);
  unsigned char* t = static_cast<unsigned char*>(m.train);
  grow(q, m.query_bytes, query_bytes);
  grow(t, m.train_bytes, train_bytes);
  m.query = q, m.train = t;
  grow(m.index, m.rows, std::size_t(queries));
  grow(m.best, m.rows_best, std::size_t(queries));
  grow(m.second, m.rows_second, std::size_t(queries));
  check(cudaMemcpy(m.query, query, query_bytes, cudaMemcpyHostToDevice), "copy query descriptors");
  if (train_bytes > 0) check(cudaMemcpy(m.train, train, train_bytes, cudaMemcpyHostToDevice), "copy train descriptors");
  const int blocks = (queries + kThreads - 1) / kThreads;
  twoNearestKernel<Word, Metric><<<blocks, kThreads, shared_bytes>>>(
      static_cast<const Word*>(m.query), queries, static_cast<const Word*>(m.train), trains, width, m.index, m.best,
      m.second);
  check(cudaGetLastError(), "two-nearest kernel launch");
  check(cudaMemcpy(index, m.index, std::size_t(queries) * sizeof(int), cudaMemcpyDeviceToHost), "copy indices");
  check(cudaMemcpy(best, m.best, std::size_t(queries) * sizeof(float), cudaMemcpyDeviceToHost), "copy distances");
  check(cudaMemcpy(second, m.second, std::size_t(queries) * sizeof(float), cudaMemcpyDeviceToHost), "copy distances");
}

}  // namespace

void twoNearestL2(MatchBuffers& buffers, const float* query, int queries, const float* train, int trains, int width,
                  int* index, float* best, float* second) {
  twoNearest<float, L2>(buffers, query, queries, train, trains, width, index, best, second);
}

void twoNearestHamming(MatchBuffers& buffers, const std::uint32_t* query, int queries, const std::uint32_t* train,
                       int trains, int width, int* index, float* best, float* second) {
  twoNearest<std::uint32_t, Hamming>(buffers, query, queries, train, trains, width, index, best, second);
}

}  // namespace bundletrack::cuda::detail
