// Must not compile: int is no LinearSolver. The CMake test expects the concept's name in the error.
#include "bundletrack/tracker.hpp"

int main() {
  bundletrack::Tracker<bundletrack::DefaultEnergy, int> tracker(bundletrack::PinholeCameraf{500, 500, 320, 240});
  (void)tracker;
}
