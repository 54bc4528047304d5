#pragma once

// Kernel bodies written once for both compilers: nvcc builds them for the device, and the host
// compiler builds the same functions for the tests that check them against the CPU policies on
// machines without a GPU.
#ifdef __CUDACC__
#define BUNDLETRACK_HOST_DEVICE __host__ __device__
#else
#define BUNDLETRACK_HOST_DEVICE
#endif
