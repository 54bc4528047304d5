// Must not compile: int is no LinearSolver. The CMake test expects the concept's name in the error.
#include "bundletrack/default_tracker.hpp"

int main() {
  namespace bt = bundletrack;
  bt::Tracker<bt::DefaultEnergy, int, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, bt::SurfaceAgreement> tracker(
      bt::PinholeCameraf{500, 500, 320, 240});
  (void)tracker;
}
