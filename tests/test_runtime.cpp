// makeTracker: the trackers a configuration describes, against the same trackers composed at
// compile time, and the combinations it refuses.
#include <doctest/doctest.h>

#include <stdexcept>

#include "bundletrack/default_tracker.hpp"
#include "bundletrack/masks/propagated_masks.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

namespace {

/// Poses of `frames` frames of the default synthetic sequence (every mask given, or only the first).
template <typename Tracker>
std::vector<bt::SE3d> poses(Tracker& tracker, int frames, bool first_mask_only = false) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = frames;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  std::vector<bt::SE3d> out;
  for (int i = 0; i < frames; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame =
        bt::makeFrame(std::to_string(i), f.color, f.depth, first_mask_only && i > 0 ? cv::Mat() : f.mask, camera);
    out.push_back((i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame)).T_cam_obj);
  }
  return out;
}

double largestDifference(const std::vector<bt::SE3d>& a, const std::vector<bt::SE3d>& b) {
  REQUIRE(a.size() == b.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    largest = std::max(largest, (a[i].matrix() - b[i].matrix()).cwiseAbs().maxCoeff());
  return largest;
}

const bt::PinholeCameraf kCamera = synth::SyntheticSequenceSettings().camera.cast<float>();

}  // namespace

TEST_CASE("makeTracker builds the tracker composed at compile time: the same poses, given or propagated masks") {
  const int frames = 12;
  bt::DefaultTracker composed(kCamera);
  const auto expected = poses(composed, frames);
  const auto made = bt::makeTracker(bt::Config(), kCamera);
  CHECK(largestDifference(poses(*made, frames), expected) == 0.0);

  bt::Tracker<bt::DefaultEnergy, bt::PCG, bt::SiftFeatures, bt::PropagatedMasks, bt::Ransac, bt::SurfaceAgreement>
      propagated(kCamera);
  bt::Config config;
  config.masks = "propagated";
  const auto made_propagated = bt::makeTracker(config, kCamera);
  CHECK(largestDifference(poses(*made_propagated, frames, true), poses(propagated, frames, true)) == 0.0);
}

TEST_CASE("makeTracker applies the settings it is given and the coarse tracker it names") {
  const int frames = 8;
  bt::Config config;
  config.tracker = "coarse";
  bt::DefaultCoarseTracker coarse;
  const auto made = bt::makeTracker(config, kCamera);
  CHECK(made->keyframeCount() == 0);
  CHECK(largestDifference(poses(*made, frames), poses(coarse, frames)) == 0.0);
  // A setting that matters moves the poses: a Huber delta a hundred times smaller.
  bt::Config tight;
  tight.dense_loss.delta = tight.feature_loss.delta = 5e-5;
  bt::DefaultTracker composed(kCamera);
  CHECK(largestDifference(poses(*bt::makeTracker(tight, kCamera), frames), poses(composed, frames)) > 1e-6);
}

TEST_CASE("serial and parallel execution give bit-identical poses") {
  const int frames = 10;
  bt::Config serial;
  serial.execution = bt::Execution::Serial;
  const auto one_thread = bt::makeTracker(serial, kCamera), all_cores = bt::makeTracker(bt::Config(), kCamera);
  CHECK(largestDifference(poses(*one_thread, frames), poses(*all_cores, frames)) == 0.0);
}

TEST_CASE("makeTracker refuses combinations that do not exist, naming the keys") {
  const auto problem = [](const bt::Config& config) -> std::string {
    try {
      bt::makeTracker(config, kCamera);
    } catch (const std::invalid_argument& error) {
      return error.what();
    } catch (const std::runtime_error& error) {
      return std::string("runtime: ") + error.what();
    }
    return "";
  };
  bt::Config coarse_propagated;
  coarse_propagated.tracker = "coarse";
  coarse_propagated.masks = "propagated";
  CHECK(problem(coarse_propagated).find("tracker.type = coarse with masks.source = propagated") != std::string::npos);
  bt::Config coarse_gpu;
  coarse_gpu.tracker = "coarse";
  coarse_gpu.device = "gpu";
  CHECK(problem(coarse_gpu).find("compute.device = gpu") != std::string::npos);
  bt::Config unknown;
  unknown.features = "surf";
  CHECK(problem(unknown) == "features.type = 'surf': expected sift | orb | akaze");
  bt::Config gpu;
  gpu.device = "gpu";
  const std::string no_gpu = problem(gpu);
  // On a machine with a device and the backend, the GPU tracker is built.
  if (!no_gpu.empty()) CHECK(no_gpu.rfind("runtime: compute.device is gpu, but ", 0) == 0);
}
