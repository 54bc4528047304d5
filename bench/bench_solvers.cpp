// The pose graph's pieces on data from a tracker run: linear solvers on its normal equations, PCG
// (the tracker's truncated 5 iterations, and to convergence) vs dense LDLT vs Eigen's
// ConjugateGradient, for graphs of 2..64 nodes; residual evaluation and assembly throughput of the
// feature, dense and photometric terms; greedy keyframe selection. Systems come from a synthetic hand-held box tracked with keyframes every
// 2.5 degrees, so that 64 keyframes exist; edges carry matched and RANSAC-pruned features and the
// dense term, as in the tracker.
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>
#include <map>
#include <random>

#include "bundletrack/synth/synthetic_sequence.hpp"
#include "bundletrack/default_tracker.hpp"
#include "bundletrack/solvers/dense_ldlt.hpp"

namespace bt = bundletrack;

namespace {

struct System {
  Eigen::MatrixXd H;
  Eigen::VectorXd rhs;
};

/// The keyframes of one tracker run (synthetic hand-held box, keyframes every 2.5 degrees).
struct TrackedKeyframes {
  std::vector<bt::Keyframe> keyframes;
  bt::PinholeCameraf camera;
};

const TrackedKeyframes& trackedKeyframes() {
  static const TrackedKeyframes run = [] {
    TrackedKeyframes out;
    bt::synth::SyntheticSequenceSettings settings;
    settings.frames = 300;
    settings.speed = 1.5;
    const bt::synth::SyntheticScene scene(settings);
    out.camera = settings.camera.cast<float>();
    bt::TrackerSettings tracker_settings;
    tracker_settings.new_keyframe_rotation_deg = 2.5;
    bt::DefaultTracker tracker(out.camera, tracker_settings);
    for (int i = 0; i < settings.frames; ++i) {
      const auto f = scene.frame(i);
      const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, out.camera);
      if (i == 0) tracker.initialize(frame, f.T_cam_obj);
      else tracker.track(frame);
    }
    for (std::size_t k = 0; k < tracker.keyframes().size(); ++k) out.keyframes.push_back(tracker.keyframes()[k]);
    return out;
  }();
  return run;
}

/// The pose graph over the first `nodes` keyframes: all pairs, features matched with the pose gate
/// and pruned by RANSAC, as the tracker builds it.
const bt::PoseGraph& graphOfSize(int size) {
  static std::map<int, bt::PoseGraph> graphs;
  if (auto found = graphs.find(size); found != graphs.end()) return found->second;
  const TrackedKeyframes& run = trackedKeyframes();
  bt::PoseGraph& graph = graphs[size];
  const int count = std::min<int>(size, int(run.keyframes.size()));
  for (int k = 0; k < count; ++k)
    graph.nodes.push_back(&run.keyframes[std::size_t(k)]), graph.poses.push_back(run.keyframes[std::size_t(k)].T_cam_obj);
  const bt::SiftFeatures sift;
  const bt::Ransac ransac;
  for (int a = 0; a < count; ++a) {
    for (int b = a + 1; b < count; ++b) {
      const bt::MatchGate gate{(graph.poses[b] * graph.poses[a].inverse()).cast<float>(), {}};
      const auto m = sift.match(graph.nodes[a]->features, graph.nodes[b]->features, gate);
      const auto pruned = ransac.estimate(graph.nodes[a]->features, graph.nodes[b]->features, m);
      std::vector<bt::FeatureMatch>& inliers = graph.owned_matches.emplace_back();
      for (const int k : pruned.inliers) inliers.push_back(m[std::size_t(k)]);
      graph.edges.push_back({a, b});
      graph.matches.push_back(&inliers);
    }
  }
  return graph;
}

/// Normal equations of the first `nodes` keyframes (built once, then cached).
const System& systemOfSize(int nodes) {
  static std::map<int, System> systems;
  if (auto found = systems.find(nodes); found != systems.end()) return found->second;
  const bt::PoseGraph& graph = graphOfSize(nodes);
  const bt::DefaultEnergy energy;
  bt::Linearisation at;
  bt::assembleNormalEquations(energy.over(graph), graph.poses, at);
  System system{at.H, -at.b};
  if (system.rhs.norm() == 0.0) system.rhs.setOnes();  // at the optimum b = 0: solve for a unit load instead
  return systems.emplace(nodes, std::move(system)).first->second;
}

/// Residual evaluation and normal-equation assembly of one energy term over a whole graph.
template <typename EnergyT>
void assemble(benchmark::State& state, const EnergyT& energy = {}) {
  const bt::PoseGraph& graph = graphOfSize(int(state.range(0)));
  const auto problem = energy.over(graph);
  bt::Linearisation at;
  for (auto _ : state) {
    bt::assembleNormalEquations(problem, graph.poses, at);
    benchmark::DoNotOptimize(at.H.data());
  }
  state.counters["residuals"] = at.residuals;
  state.counters["residuals_per_second"] = benchmark::Counter(double(at.residuals), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_AssembleFeatureTerm(benchmark::State& state) {
  assemble<bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>>>(state);
}

void BM_AssembleDenseTerm(benchmark::State& state) {
  assemble<bt::Energy<bt::Term<bt::DensePointToPlane, bt::HuberLoss>>>(state);
}

void BM_AssemblePhotometricTerm(benchmark::State& state) {
  using Photometric = bt::Term<bt::DensePhotometric, bt::HuberLoss>;
  assemble(state, bt::Energy<Photometric>{{Photometric{{}, bt::HuberLoss{bt::DensePhotometric::kHuberDelta}, 1.0}}});
}

/// Greedy selection of 15 keyframes (paper IV-C) from pools of growing size.
void BM_SelectKeyframes(benchmark::State& state) {
  bt::KeyframePool pool(std::size_t(state.range(0)));
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  for (int k = 0; k < state.range(0); ++k) {
    bt::Keyframe keyframe;
    keyframe.id = k;
    keyframe.T_cam_obj = bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(normal(rng), normal(rng), normal(rng))), {0, 0, 0});
    pool.add(std::move(keyframe));
  }
  const bt::SO3d current = bt::SO3d::exp(Eigen::Vector3d(0.1, 0.2, 0.3));
  for (auto _ : state) benchmark::DoNotOptimize(pool.select(current, 15));
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
BENCHMARK(BM_AssembleFeatureTerm)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AssembleDenseTerm)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_AssemblePhotometricTerm)->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SelectKeyframes)->RangeMultiplier(4)->Range(16, 1024)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
