// Scoring a frame against a large model (issue 18: a 10^6-point model with poses far from the
// truth did not finish): ADD-S of one pose -- a nearest-neighbour query per model point -- beside
// ADD of the same pose (no search: the baseline of the same run), for poses 1 cm and 50 cm from
// the truth, models of 10^4 to 10^6 points; building the k-d tree on its own; and scoreSequence,
// which scores a model of more than kMostScoredPoints on an even subsample.
#include <benchmark/benchmark.h>

#include <random>

#include "bundletrack/eval/sequence_score.hpp"

namespace bt = bundletrack;

namespace {

/// Points on the surface of a 20 cm box.
std::vector<Eigen::Vector3f> boxSurface(int count) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  std::uniform_int_distribution<int> face(0, 5);
  std::vector<Eigen::Vector3f> points(static_cast<std::size_t>(count));
  for (auto& p : points) {
    p = Eigen::Vector3f(u(rng), u(rng), u(rng));
    const int f = face(rng);
    p[f / 2] = f % 2 ? 0.1f : -0.1f;
  }
  return points;
}

const bt::SE3d kTruth(bt::SO3d::exp(Eigen::Vector3d(0.2, -0.1, 0.4)), Eigen::Vector3d(0.0, 0.0, 0.8));

bt::SE3d offBy(double metres) {
  return bt::SE3d(kTruth.rotation() * bt::SO3d::exp(Eigen::Vector3d(0.0, 0.05, 0.0)),
                  kTruth.translation() + Eigen::Vector3d(metres, 0.0, 0.0));
}

void BM_BuildTree(benchmark::State& state) {
  const auto model = boxSurface(int(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(bt::KdTree3(model).size());
}

void BM_AddS(benchmark::State& state) {
  const auto model = boxSurface(int(state.range(0)));
  const bt::KdTree3 tree(model);
  const bt::SE3d estimate = offBy(state.range(1) * 0.01);
  for (auto _ : state) benchmark::DoNotOptimize(bt::averageDistanceSymmetric(model, tree, kTruth, estimate));
}

void BM_Add(benchmark::State& state) {
  const auto model = boxSurface(int(state.range(0)));
  const bt::SE3d estimate = offBy(state.range(1) * 0.01);
  for (auto _ : state) benchmark::DoNotOptimize(bt::averageDistance(model, kTruth, estimate));
}

/// scoreSequence on ten frames: a model above kMostScoredPoints is scored on its subsample.
void BM_ScoreTenFrames(benchmark::State& state) {
  const auto model = boxSurface(int(state.range(0)));
  const std::vector<bt::SE3d> truth(10, kTruth), estimate(10, offBy(0.01));
  for (auto _ : state) benchmark::DoNotOptimize(bt::scoreSequence(model, truth, estimate).adds_auc);
}

}  // namespace

BENCHMARK(BM_ScoreTenFrames)->Arg(10000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildTree)->Arg(10000)->Arg(1000000)->Unit(benchmark::kMillisecond);
// Arguments: model points, centimetres from the truth.
BENCHMARK(BM_AddS)->ArgsProduct({{10000, 1000000}, {1, 50}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Add)->ArgsProduct({{10000, 1000000}, {1, 50}})->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
