#include "compose.hpp"

namespace bundletrack::runtime {

std::unique_ptr<AnyTracker> cpuTrackerWithGivenMasks(const Config& config, const PinholeCameraf& camera) {
  return cpuTracker(config, camera, GivenMasks());
}

}  // namespace bundletrack::runtime
