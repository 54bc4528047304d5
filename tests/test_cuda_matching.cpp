// The GPU descriptor matcher against OpenCV's brute-force matcher and the CPU correspondence
// source, and the tracker composed of GPU policies against the CPU tracker; skips without a CUDA
// device.
#include <doctest/doctest.h>

#include "bundletrack/cuda/tracker.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "bundletrack/default_tracker.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

static_assert(bt::CorrespondenceSource<bt::cuda::GpuMatched<bt::SiftFeatures>>, "GPU matching composes like the CPU source");

namespace {

/// Features of frames 0 and `later` of the default synthetic sequence.
template <typename Source>
std::pair<bt::FrameFeatures, bt::FrameFeatures> featurePair(Source source, int later) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = later + 1;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const auto frame = [&](int i) {
    const synth::SyntheticFrame f = scene.frame(i);
    return bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
  };
  return {source.detect(frame(0)), source.detect(frame(later))};
}

template <typename Source>
void checkAgainstOpenCv(Source source) {
  const auto [a, b] = featurePair(source, 5);
  REQUIRE(a.size() > 100);
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(a.norm_type).knnMatch(a.descriptors, b.descriptors, knn, 2);
  const auto gpu = bt::cuda::DescriptorMatcher().twoNearest(a.descriptors, b.descriptors, a.norm_type);
  REQUIRE(gpu.size() == knn.size());
  int same_index = 0;
  for (std::size_t k = 0; k < knn.size(); ++k) {
    same_index += gpu[k].index == knn[k][0].trainIdx;
    CHECK(gpu[k].best == doctest::Approx(knn[k][0].distance).epsilon(1e-4));
    CHECK(gpu[k].second == doctest::Approx(knn[k][1].distance).epsilon(1e-4));
  }
  // Indices differ only where two train rows tie to float rounding.
  CHECK(same_index >= int(0.99 * double(knn.size())));
  bt::MatchSettings exhaustive;
  exhaustive.guided = false;
  const bt::MatchGate gate{bt::SE3f(), 0.5f, 90.0f};
  for (const auto& g : {std::optional<bt::MatchGate>(), std::optional(gate)}) {
    const auto cpu = bt::matchFeatures(a, b, exhaustive, g);
    const auto on_gpu = bt::cuda::GpuMatched<Source>(source, exhaustive).match(a, b, g);
    int common = 0;
    for (const auto& m : on_gpu) common += std::find(cpu.begin(), cpu.end(), m) != cpu.end();
    CHECK(common >= int(0.99 * double(cpu.size())));
    CHECK(int(on_gpu.size()) - common <= int(0.01 * double(cpu.size())) + 1);
  }
}

}  // namespace

TEST_CASE("GPU two-nearest search equals OpenCV's brute-force matcher (SIFT, ORB)") {
  if (!bt::cuda::deviceAvailable()) {
    MESSAGE("SKIPPED: no CUDA device");
    return;
  }
  checkAgainstOpenCv(bt::SiftFeatures());
  checkAgainstOpenCv(bt::OrbFeatures());
}

TEST_CASE("tracker composed of GPU policies (PCG, matching, dense term, RANSAC) tracks as the CPU tracker does") {
  if (!bt::cuda::deviceAvailable()) {
    MESSAGE("SKIPPED: no CUDA device");
    return;
  }
  synth::SyntheticSequenceSettings settings;
  settings.frames = 60;
  settings.speed = 2.0;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  bt::SiftSettings sift;
  sift.matching.guided = false;  // the GPU matcher is exhaustive
  bt::DefaultTracker cpu(camera, {}, {}, {}, bt::SiftFeatures(sift));
  bt::cuda::Tracker<bt::SiftFeatures> gpu(
      camera, {}, {}, {}, bt::cuda::GpuMatched<bt::SiftFeatures>(bt::SiftFeatures(sift), sift.matching));
  std::vector<bt::SE3d> truth, on_cpu, on_gpu;
  for (int i = 0; i < settings.frames; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
    truth.push_back(f.T_cam_obj);
    on_cpu.push_back((i == 0 ? cpu.initialize(frame, f.T_cam_obj) : cpu.track(frame)).T_cam_obj);
    on_gpu.push_back((i == 0 ? gpu.initialize(frame, f.T_cam_obj) : gpu.track(frame)).T_cam_obj);
  }
  const auto cpu_score = bt::scoreSequence(model, truth, on_cpu), gpu_score = bt::scoreSequence(model, truth, on_gpu);
  MESSAGE("ADD-S AUC: CPU " << cpu_score.adds_auc << ", GPU " << gpu_score.adds_auc);
  // Float PCG and rounding-level match differences let the two drift apart by a little.
  CHECK(gpu_score.adds_auc >= cpu_score.adds_auc - 1.0);
  CHECK(gpu_score.adds_auc >= 95.0);
}
