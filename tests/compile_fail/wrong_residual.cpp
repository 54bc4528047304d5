// Must not compile: a residual that does not say what it reads of an edge (no Input, no input()).
// The CMake test expects the concept's name in the error.
#include "bundletrack/energy.hpp"

struct NoInput {
  template <typename Loss>
  void linearise(const bundletrack::EdgeView&, const Loss&, double, bundletrack::PairSystem&) const {}
};

int main() {
  bundletrack::Term<NoInput, bundletrack::HuberLoss> term;
  (void)term;
}
