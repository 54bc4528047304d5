// The full tracker with the GPU policies of bundletrack::cuda (compute.device: gpu).
#include <algorithm>
#include <stdexcept>

#include "bundletrack/cuda/tracker.hpp"
#include "bundletrack/masks/propagated_masks.hpp"
#include "compose.hpp"

namespace bundletrack::runtime {

namespace {

template <typename Masks>
std::unique_ptr<AnyTracker> gpuTrackerWith(const Config& config, const PinholeCameraf& camera, Masks masks) {
  cuda::DensePointToPlane dense;
  dense.gate = config.dense.gate;
  cuda::PCG pcg;
  pcg.max_iterations = config.pcg.max_iterations;
  pcg.tolerance = std::max(config.pcg.tolerance, pcg.tolerance);  // float arithmetic goes no further
  pcg.damping = config.pcg.damping;
  return eraseTracker(cuda::Tracker<OpenCvFeatureSource, Masks>(
      camera, config.tracking, energy(config, std::move(dense)), std::move(pcg),
      cuda::GpuMatched<OpenCvFeatureSource>(featureSource(config), config.sift.matching), std::move(masks),
      cuda::Ransac(ransacSettings(config)), SurfaceAgreement(config.verification)));
}

}  // namespace

std::unique_ptr<AnyTracker> gpuTracker(const Config& config, const PinholeCameraf& camera) {
  if (!cuda::deviceAvailable())
    throw std::runtime_error("compute.device is gpu, but no CUDA device is available (is the NVIDIA driver loaded?)");
  if (config.masks == "propagated") return gpuTrackerWith(config, camera, PropagatedMasks(config.propagated_masks));
  return gpuTrackerWith(config, camera, GivenMasks(givenMaskSettings(config)));
}

}  // namespace bundletrack::runtime
