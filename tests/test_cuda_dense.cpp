// The GPU dense point-to-plane term against its CPU twin on the same keyframe pairs; skips
// without a CUDA device.
#include <doctest/doctest.h>

#include <algorithm>
#include <initializer_list>

#include "bundletrack/cuda/dense_point_to_plane.hpp"
#include "bundletrack/cuda/pcg.hpp"
#include "bundletrack/energy.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "pose_graph_fixture.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

static_assert(bt::BatchResidual<bt::cuda::DensePointToPlane>, "the GPU dense term composes like the CPU one, in batches");

namespace {

/// GPU and CPU normal equations (an edge's or a graph's) agree: the same residuals up to
/// projections that round the other way at a pixel or gate boundary, and sums to float precision.
template <typename System>
void checkSame(const System& on_gpu, const System& on_cpu, int at_least) {
  REQUIRE(on_cpu.residuals > at_least);
  CHECK(std::abs(on_gpu.residuals - on_cpu.residuals) <= on_cpu.residuals / 1000 + 1);
  const double tolerance = on_gpu.residuals == on_cpu.residuals ? 1e-4 : 1e-2;
  CHECK((on_gpu.H - on_cpu.H).norm() <= tolerance * on_cpu.H.norm());
  CHECK((on_gpu.b - on_cpu.b).norm() <= tolerance * on_cpu.b.norm());
  CHECK(on_gpu.cost == doctest::Approx(on_cpu.cost).epsilon(tolerance));
}

template <typename Loss>
void compare(const bt::Keyframe& a, const bt::Keyframe& b, const bt::SE3d& T_a, const bt::SE3d& T_b, const Loss& loss,
             const bt::cuda::DensePointToPlane& gpu) {
  const bt::DensePointToPlane::Input input{a.surface, b.surface};
  bt::PairSystem on_cpu, on_gpu;
  bt::DensePointToPlane{}.linearise(input, T_a, T_b, loss, 0.7, on_cpu);
  gpu.linearise(input, T_a, T_b, loss, 0.7, on_gpu);
  checkSame(on_gpu, on_cpu, 500);
}

/// Keyframes (dense grid every 4 px) of the given frames of the default synthetic sequence and
/// their true poses.
struct SyntheticKeyframes {
  std::vector<bt::Keyframe> keyframes;
  std::vector<bt::SE3d> truth;
};

SyntheticKeyframes syntheticKeyframes(std::initializer_list<int> frames) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = std::max(frames) + 1;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const int step = 4;
  SyntheticKeyframes out;
  for (const int i : frames) {
    const synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
    out.keyframes.push_back(bt::makeKeyframe(i, frame, frame.mask, {}, f.T_cam_obj, camera, step));
    out.truth.push_back(f.T_cam_obj);
  }
  return out;
}

}  // namespace

TEST_CASE("GPU dense point-to-plane term equals the CPU term for every loss, with keyframes kept on the device") {
  if (!bt::cuda::deviceAvailable()) {
    MESSAGE("SKIPPED: no CUDA device");
    return;
  }
  const auto [keyframes, truth] = syntheticKeyframes({0, 7});
  // Poses a few millimetres and a degree off the truth, as in a Gauss-Newton iteration.
  const bt::SE3d nudge = bt::SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.003, -0.002, 0.004, 0.01, -0.015, 0.005).finished());
  const bt::cuda::DensePointToPlane gpu;
  for (int repeat = 0; repeat < 2; ++repeat) {  // the second round reads the grids kept on the device
    compare(keyframes[0], keyframes[1], truth[0], nudge * truth[1], bt::HuberLoss{}, gpu);
    compare(keyframes[0], keyframes[1], truth[0], nudge * truth[1], bt::TrivialLoss{}, gpu);
    compare(keyframes[0], keyframes[1], truth[0], nudge * truth[1], bt::CauchyLoss{}, gpu);
    compare(keyframes[0], keyframes[1], truth[0], nudge * truth[1], bt::TukeyLoss{}, gpu);
  }
  // A keyframe whose grid changed is uploaded again, not read stale.
  bt::Keyframe moved = keyframes[1];
  moved.surface.points = keyframes[1].surface.points.clone();
  moved.surface.points += cv::Scalar(0.001, 0.0, 0.0);
  compare(keyframes[0], moved, truth[0], nudge * truth[1], bt::HuberLoss{}, gpu);
}

TEST_CASE("GPU dense term assembles a whole graph in one launch as the CPU term does edge by edge") {
  if (!bt::cuda::deviceAvailable()) {
    MESSAGE("SKIPPED: no CUDA device");
    return;
  }
  const auto [keyframes, truth] = syntheticKeyframes({0, 3, 6, 9});
  // Node 0 at its true pose, the others nudged by amounts that grow along the graph.
  std::vector<bt::SE3d> poses = truth;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const double K = double(k);
    poses[k] = bt::SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.002 * K, -0.001 * K, 0.003, 0.005 * K, -0.01, 0.004).finished()) *
               truth[k];
  }
  const std::vector<bt::FeatureMatch> none;
  const bt::PoseGraph graph = allPairsGraph(keyframes, poses, none);
  bt::Linearisation cpu, on_gpu;
  const bt::Energy<bt::Term<bt::DensePointToPlane, bt::HuberLoss>> cpu_energy;
  bt::assembleNormalEquations(cpu_energy.over(graph), graph.poses, cpu);
  const bt::Energy<bt::Term<bt::cuda::DensePointToPlane, bt::HuberLoss>> gpu;
  for (int repeat = 0; repeat < 2; ++repeat) {  // the second time with the grids already on the device
    bt::assembleNormalEquations(gpu.over(graph), graph.poses, on_gpu);
    checkSame(on_gpu, cpu, 3000);
  }
}
