// Per-stage cost of turning a 640x480 depth image into points and normals, and of doing so only
// inside an object's region; a smoothing pass with the plane fit (the default) and the mean.
#include <benchmark/benchmark.h>

#include <random>

#include "bundletrack/core/rgbd_frame.hpp"

namespace bt = bundletrack;

namespace {

const bt::PinholeCameraf kCamera{525.0f, 525.0f, 319.5f, 239.5f};

// A slanted plane at about 1 m with 2 mm Gaussian noise and 2% dropouts.
cv::Mat noisyDepth() {
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  cv::Mat depth(480, 640, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u)
      depth.at<float>(v, u) = uniform(rng) < 0.02f ? 0.0f : 0.8f + 0.0006f * float(u) + noise(rng);
  return depth;
}

void BM_Erode(benchmark::State& state) {
  const cv::Mat depth = noisyDepth();
  for (auto _ : state) benchmark::DoNotOptimize(bt::erodeDepth(depth, {}));
}

void BM_SmoothOnePass(benchmark::State& state) {
  const cv::Mat depth = noisyDepth();
  for (auto _ : state) benchmark::DoNotOptimize(bt::smoothDepth(depth, {}));
}

// The same pass with the original code's weighted mean instead of the default plane fit.
void BM_SmoothOnePassMean(benchmark::State& state) {
  const cv::Mat depth = noisyDepth();
  bt::DepthFilterSettings mean;
  mean.smoothing = bt::DepthSmoothing::Mean;
  for (auto _ : state) benchmark::DoNotOptimize(bt::smoothDepth(depth, mean));
}

void BM_PointsAndNormals(benchmark::State& state) {
  const cv::Mat depth = noisyDepth();
  for (auto _ : state) benchmark::DoNotOptimize(bt::estimateNormals(bt::unprojectDepth(depth, kCamera)));
}

void BM_MakeFrame(benchmark::State& state) {
  const cv::Mat depth = noisyDepth();
  const cv::Mat color(depth.size(), CV_8UC3, cv::Scalar::all(128));
  for (auto _ : state) benchmark::DoNotOptimize(bt::makeFrame("0", color, depth, {}, kCamera));
}

// Only a 160x160 region (an object's box at about 1 m, Tracker::regionOfInterest) processed.
void BM_MakeFrameRegion160(benchmark::State& state) {
  const cv::Mat depth = noisyDepth();
  const cv::Mat color(depth.size(), CV_8UC3, cv::Scalar::all(128));
  for (auto _ : state) benchmark::DoNotOptimize(bt::makeFrame("0", color, depth, {}, kCamera, {}, {240, 160, 160, 160}));
}

}  // namespace

BENCHMARK(BM_Erode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SmoothOnePass)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SmoothOnePassMean)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointsAndNormals)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MakeFrame)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MakeFrameRegion160)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
