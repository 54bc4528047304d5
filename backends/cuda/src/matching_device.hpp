#pragma once

// The boundary between host code and the CUDA translation unit: plain pointers and integers only.

#include <cstdint>

namespace bundletrack::cuda::detail {

/// Device buffers of one matcher, grown on demand (owned by the .cu side).
struct MatchBuffers;

MatchBuffers* createMatchBuffers();
void destroyMatchBuffers(MatchBuffers* buffers);

/// For each of the `queries` rows of `query`, the index of the nearest of the `trains` rows of
/// `train` and the nearest and second-nearest distances (infinity where there is none). Rows are
/// `width` floats (L2 distance) or `width` 32-bit words (Hamming distance), row-major, on the host.
void twoNearestL2(MatchBuffers& buffers, const float* query, int queries, const float* train, int trains, int width,
                  int* index, float* best, float* second);
void twoNearestHamming(MatchBuffers& buffers, const std::uint32_t* query, int queries, const std::uint32_t* train,
                       int trains, int width, int* index, float* best, float* second);

}  // namespace bundletrack::cuda::detail
