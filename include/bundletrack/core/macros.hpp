#pragma once

// Functions that must run on the host and inside CUDA kernels carry this annotation.
#if defined(__CUDACC__)
#define BUNDLETRACK_HOST_DEVICE __host__ __device__
#else
#define BUNDLETRACK_HOST_DEVICE
#endif
