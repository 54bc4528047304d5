// Must not compile: a Term whose loss has no evaluate(s). The CMake test expects the concept's name.
#include "bundletrack/energy.hpp"
#include "bundletrack/residuals/feature_point_to_point.hpp"

struct NotALoss {};

int main() {
  bundletrack::Term<bundletrack::FeaturePointToPoint, NotALoss> term;
  (void)term;
}
