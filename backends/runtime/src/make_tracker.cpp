#include "bundletrack/runtime/make_tracker.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "bundletrack/masks/propagated_masks.hpp"
#include "compose.hpp"

namespace bundletrack {

namespace {

/// A Config filled in by code rather than read from a file can hold any text in a choice.
void requireKnownChoices(Config config) {
  for (const ConfigEntry& entry : configEntries(config)) {
    const auto* choice = std::get_if<ConfigChoice>(&entry.value);
    if (!choice || std::find(choice->names.begin(), choice->names.end(), choice->get()) != choice->names.end()) continue;
    throw std::invalid_argument(entry.name() + " = '" + choice->get() + "': expected " + choice->alternatives());
  }
}

}  // namespace

#ifndef BUNDLETRACK_HAS_CUDA
std::unique_ptr<AnyTracker> runtime::gpuTracker(const Config&, const PinholeCameraf&) {
  throw std::runtime_error("compute.device is gpu, but this build has no CUDA backend (configure with "
                           "-DBUNDLETRACK_CUDA=ON on a machine with nvcc)");
}
#endif

std::unique_ptr<AnyTracker> makeTracker(const Config& config, const PinholeCameraf& camera) {
  requireKnownChoices(config);
  if (config.tracker == "coarse") {
    if (config.masks == "propagated")
      throw std::invalid_argument("tracker.type = coarse with masks.source = propagated: propagated masks need the "
                                  "full tracker (they render its keyframes)");
    if (config.device == "gpu")
      throw std::invalid_argument("tracker.type = coarse with compute.device = gpu: the GPU policies serve the full "
                                  "tracker; the coarse tracker runs on the CPU");
    return eraseTracker(CoarseTracker<OpenCvFeatureSource, Ransac>(runtime::featureSource(config),
                                                                   Ransac(runtime::ransacSettings(config)),
                                                                   {config.tracking.min_inliers}));
  }
  if (config.device == "gpu") return runtime::gpuTracker(config, camera);
  if (config.masks == "propagated") return runtime::cpuTracker(config, camera, PropagatedMasks(config.propagated_masks));
  return runtime::cpuTracker(config, camera, GivenMasks(runtime::givenMaskSettings(config)));
}

}  // namespace bundletrack
