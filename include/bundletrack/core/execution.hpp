#pragma once

#include <opencv2/core.hpp>

namespace bundletrack {

/// Whether a loop over independent items may use several threads. Every parallel loop of the
/// library writes each item's result to its own slot and combines them in item order afterwards,
/// so both choices give bit-identical results.
enum class Execution { Serial, Parallel };

/// A policy whose const member functions may run on several threads at once: it keeps no state
/// between calls (`static constexpr bool kConcurrentCalls = true`). A GPU backend's device buffers
/// are such state, so its policies leave the flag out and are called from one thread.
template <typename T>
concept ConcurrentCalls = requires { requires T::kConcurrentCalls; };

/// body(k) for k in [0, count), on OpenCV's thread pool when `execution` is Parallel.
template <typename Body>
void forEachIndex(Execution execution, int count, Body&& body) {
  if (execution == Execution::Serial) {
    for (int k = 0; k < count; ++k) body(k);
    return;
  }
  cv::parallel_for_(cv::Range(0, count), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) body(k);
  });
}

}  // namespace bundletrack
