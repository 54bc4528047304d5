#pragma once

// The boundary between host code and the CUDA translation unit: plain pointers and integers only.

#include <cstdint>

namespace bundletrack::cuda::detail {

/// Device buffers of one trial scorer, grown on demand (owned by the .cu side).
struct RansacBuffers;

RansacBuffers* createRansacBuffers();
void destroyRansacBuffers(RansacBuffers* buffers);

/// Copies n matched pairs, 12 floats each (first point, second point, first normal, second normal).
void uploadPairs(RansacBuffers& buffers, const float* pairs, int n);

/// What a batch of trials is drawn and scored with (RansacSettings and InlierGate as plain data).
struct TrialParameters {
  std::uint64_t seed;
  float min_sample_spread;
  float max_squared_distance;
  float cos_max_angle;
};

/// Trials first .. first + count - 1 on the uploaded pairs, two launches: one thread per trial
/// draws and fits its sample (fitTrial), one block per trial counts its inliers (isInlier). Copies
/// back fits (count x 12 doubles, row-major 3x4), valid (count bytes) and counts (0 where not
/// valid).
void scoreTrials(RansacBuffers& buffers, const TrialParameters& parameters, int first, int count, double* fits,
                 unsigned char* valid, int* counts);

}  // namespace bundletrack::cuda::detail
