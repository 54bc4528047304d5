// Must not compile: a Term whose loss has no evaluate(s). The CMake test expects the concept's name.
#include "bundletrack/default_tracker.hpp"

struct NotALoss {};

int main() {
  bundletrack::Term<bundletrack::FeaturePointToPoint, NotALoss> term;
  (void)term;
}
