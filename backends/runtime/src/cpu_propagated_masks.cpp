#include "bundletrack/masks/propagated_masks.hpp"
#include "compose.hpp"

namespace bundletrack::runtime {

std::unique_ptr<AnyTracker> cpuTrackerWithPropagatedMasks(const Config& config, const PinholeCameraf& camera) {
  return cpuTracker(config, camera, PropagatedMasks(config.propagated_masks));
}

}  // namespace bundletrack::runtime
