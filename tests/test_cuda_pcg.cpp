// The GPU PCG policy against its CPU twin on the same systems; skips without a CUDA device.
#include <doctest/doctest.h>

#include "bundletrack/cuda/pcg.hpp"
#include "bundletrack/solvers/pcg.hpp"
#include "pose_graph_system.hpp"

namespace bt = bundletrack;

static_assert(bt::LinearSolver<bt::cuda::PCG>, "the GPU PCG composes like the CPU one");

TEST_CASE("GPU PCG equals CPU PCG (same iterations) and converges to the dense solve") {
  if (!bt::cuda::deviceAvailable()) {
    MESSAGE("SKIPPED: no CUDA device");
    return;
  }
  for (const int nodes : {2, 15, 64}) {
    CAPTURE(nodes);
    Eigen::MatrixXd H;
    Eigen::VectorXd rhs, x_cpu, x_gpu;
    poseGraphSystem(nodes, unsigned(nodes), 1e-3, H, rhs);
    // The tracker's truncated solve: 5 iterations on both sides, compared step for step.
    const bt::SolveReport cpu = bt::PCG{}.solve(H, rhs, x_cpu);
    const bt::SolveReport gpu = bt::cuda::PCG{}.solve(H, rhs, x_gpu);
    CHECK(gpu.iterations == cpu.iterations);
    CHECK((x_gpu - x_cpu).norm() <= 1e-4 * x_cpu.norm());
    // Run to convergence: float arithmetic reaches the dense solution to ~1e-4.
    const auto [full, error] = solveAgainstDense(bt::cuda::PCG{}, 2000, 1e-6, H, rhs);
    CHECK(full.relative_residual < 1e-5);
    CHECK(error <= 1e-3);
  }
}
