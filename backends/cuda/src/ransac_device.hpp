#pragma once

// The boundary between host code and the CUDA translation unit: plain pointers and integers only.

namespace bundletrack::cuda::detail {

/// Device buffers of one inlier counter, grown on demand (owned by the .cu side).
struct RansacBuffers;

RansacBuffers* createRansacBuffers();
void destroyRansacBuffers(RansacBuffers* buffers);

/// Copies n matched pairs, 12 floats each (first point, second point, first normal, second normal).
void uploadPairs(RansacBuffers& buffers, const float* pairs, int n);

/// counts[h] = the uploaded pairs that hypothesis h (row-major 3x4 [R | t], 12 floats) moves within
/// max_squared_distance with normals closer than cos_max_angle; 0 where valid[h] is 0.
void countInliers(RansacBuffers& buffers, const float* hypotheses, const unsigned char* valid, int count,
                  float max_squared_distance, float cos_max_angle, int* counts);

}  // namespace bundletrack::cuda::detail
