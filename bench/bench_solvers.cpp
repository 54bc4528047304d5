// Linear solvers on pose-graph normal equations taken from a tracker run: PCG (the tracker's
// truncated 5 iterations, and to convergence) vs dense LDLT vs Eigen's ConjugateGradient, for
// graphs of 2..64 nodes. Systems come from a synthetic hand-held box tracked with keyframes every
// 2.5 degrees, so that 64 keyframes exist; edges carry matched and RANSAC-pruned features and the
// dense term, as in the tracker.
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>
#include <map>

#include "bundletrack/synth/synthetic_sequence.hpp"
#include "bundletrack/tracker.hpp"

namespace bt = bundletrack;

namespace {

struct System {
  Eigen::MatrixXd H;
  Eigen::VectorXd rhs;
};

/// Normal equations of the first `nodes` keyframes of one tracker run (built once, then cached).
const System& systemOfSize(int nodes) {
  static std::map<int, System> systems;
  static std::vector<bt::Keyframe> keyframes;
  static bt::PinholeCameraf camera;
  if (keyframes.empty()) {
    bt::synth::SyntheticSequenceSettings settings;
    settings.frames = 300;
    settings.speed = 1.5;
    const bt::synth::SyntheticScene scene(settings);
    camera = settings.camera.cast<float>();
    bt::TrackerSettings tracker_settings;
    tracker_settings.new_keyframe_rotation_deg = 2.5;
    bt::DefaultTracker tracker(camera, tracker_settings);
    for (int i = 0; i < settings.frames; ++i) {
      const auto f = scene.frame(i);
      const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
      if (i == 0) tracker.initialize(frame, f.T_cam_obj);
      else tracker.track(frame);
    }
    for (std::size_t k = 0; k < tracker.keyframes().size(); ++k) keyframes.push_back(tracker.keyframes()[k]);
  }
  if (auto found = systems.find(nodes); found != systems.end()) return found->second;
  const int count = std::min<int>(nodes, int(keyframes.size()));
  std::vector<const bt::Keyframe*> graph;
  std::vector<bt::SE3d> poses;
  for (int k = 0; k < count; ++k) graph.push_back(&keyframes[std::size_t(k)]), poses.push_back(keyframes[std::size_t(k)].T_cam_obj);
  const bt::SiftFeatures sift;
  const bt::Ransac ransac;
  std::vector<std::vector<bt::FeatureMatch>> matches;
  matches.reserve(std::size_t(count * count));
  std::vector<bt::GraphEdge> edges;
  for (int a = 0; a < count; ++a) {
    for (int b = a + 1; b < count; ++b) {
      const bt::MatchGate gate{(poses[b] * poses[a].inverse()).cast<float>()};
      const auto m = sift.match(graph[a]->features, graph[b]->features, gate);
      const auto pruned = ransac.estimate(graph[a]->features, graph[b]->features, m);
      matches.emplace_back();
      for (const int k : pruned.inliers) matches.back().push_back(m[std::size_t(k)]);
      edges.push_back({a, b, &matches.back()});
    }
  }
  System system;
  Eigen::VectorXd b;
  int residuals = 0;
  bt::assembleNormalEquations(bt::DefaultEnergy{}, graph, edges, bt::downsampledCamera(camera, 4), poses, system.H, b,
                              residuals);
  system.rhs = -b;
  if (system.rhs.norm() == 0.0) system.rhs.setOnes();  // at the optimum b = 0: solve for a unit load instead
  return systems.emplace(nodes, std::move(system)).first->second;
}

template <typename Solve>
void run(benchmark::State& state, Solve&& solve) {
  const System& system = systemOfSize(int(state.range(0)));
  Eigen::VectorXd x;
  for (auto _ : state) {
    solve(system, x);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["unknowns"] = double(system.H.rows());
  state.counters["rel_residual"] = (system.H * x - system.rhs).norm() / system.rhs.norm();
}

void BM_PCG5(benchmark::State& state) {
  run(state, [](const System& s, Eigen::VectorXd& x) { bt::PCG{}.solve(s.H, s.rhs, x); });
}

void BM_PCGConverged(benchmark::State& state) {
  bt::PCG pcg;
  pcg.max_iterations = 10000;
  pcg.tolerance = 1e-8;
  run(state, [&](const System& s, Eigen::VectorXd& x) { pcg.solve(s.H, s.rhs, x); });
}

void BM_DenseLDLT(benchmark::State& state) {
  run(state, [](const System& s, Eigen::VectorXd& x) { bt::DenseLDLT{}.solve(s.H, s.rhs, x); });
}

void BM_EigenConjugateGradient(benchmark::State& state) {
  run(state, [](const System& s, Eigen::VectorXd& x) {
    Eigen::ConjugateGradient<Eigen::MatrixXd, Eigen::Lower | Eigen::Upper> cg;
    cg.setTolerance(1e-8);
    cg.compute(s.H);
    x = cg.solve(s.rhs);
  });
}

}  // namespace

BENCHMARK(BM_PCG5)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PCGConverged)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DenseLDLT)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EigenConjugateGradient)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
