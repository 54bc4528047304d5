// RANSAC with inliers counted on the GPU against the CPU RANSAC on the same matches; skips
// without a CUDA device.
#include <doctest/doctest.h>

#include "bundletrack/cuda/pcg.hpp"
#include "bundletrack/cuda/ransac.hpp"
#include "bundletrack/eval/pose_metrics.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

static_assert(bt::FeatureRegistration<bt::cuda::Ransac>, "the GPU RANSAC composes like the CPU one");

TEST_CASE("GPU RANSAC (trials drawn, fitted and scored on the GPU) finds the CPU RANSAC's pose and inliers") {
  if (!bt::cuda::deviceAvailable()) {
    MESSAGE("SKIPPED: no CUDA device");
    return;
  }
  synth::SyntheticSequenceSettings settings;
  settings.frames = 11;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  bt::SiftFeatures sift;
  const auto features = [&](int i) {
    const synth::SyntheticFrame f = scene.frame(i);
    return sift.detect(bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera));
  };
  const bt::FrameFeatures first = features(0);
  const bt::cuda::Ransac gpu;
  for (const int later : {1, 5, 10}) {
    CAPTURE(later);
    const bt::FrameFeatures second = features(later);
    const auto matches = sift.match(first, second);
    REQUIRE(matches.size() > 30);
    const bt::RansacResult cpu = bt::Ransac().estimate(first, second, matches);
    const bt::RansacResult on_gpu = gpu.estimate(first, second, matches);
    REQUIRE(cpu.found());
    REQUIRE(on_gpu.found());
    // Float rounding of a distance at the 5 mm boundary may flip a match, nothing more.
    CHECK(std::abs(int(on_gpu.inliers.size()) - int(cpu.inliers.size())) <= 2);
    CHECK(bt::rotationErrorDeg(cpu.T_second_first, on_gpu.T_second_first) < 0.01);
    CHECK(bt::translationError(cpu.T_second_first, on_gpu.T_second_first) < 1e-4);
    // Same samples, so the adaptive stop comes in the same batch unless a flipped match changed
    // the best count on the way.
    if (on_gpu.inliers.size() == cpu.inliers.size()) CHECK(std::abs(on_gpu.trials - cpu.trials) <= bt::RansacSettings{}.batch);
  }
}
