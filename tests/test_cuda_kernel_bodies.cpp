// The bodies of the GPU kernels, compiled for the host from the same headers nvcc compiles, run
// serially against the CPU policies: the association, gates, Jacobians and losses of the dense
// term, the RANSAC inlier test, the two-nearest search and the PCG loop, together with the host
// code that packs their inputs. Needs no device; what it cannot cover (launches, reductions across
// threads, device memory) is left to the GPU tests.
#include <doctest/doctest.h>

#include <random>

#include <Eigen/Cholesky>

#include "bundletrack/cuda/dense_point_to_plane.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/registration/ransac.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/cuda/pcg.hpp"
#include "bundletrack/solvers/pcg.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "dense_cell.hpp"
#include "dense_host.hpp"
#include "matching_host.hpp"
#include "matching_metric.hpp"
#include "pcg_host.hpp"
#include "pcg_loop.hpp"
#include "pose_graph_system.hpp"
#include "ransac_body.hpp"
#include "ransac_host.hpp"
#include "rigid_fit.hpp"

namespace bt = bundletrack;
namespace detail = bundletrack::cuda::detail;
namespace synth = bundletrack::synth;

namespace {

/// Frames 0 and `later` of the default synthetic sequence, their true poses and the camera.
struct FramePair {
  std::vector<bt::RgbdFrame> frames;
  std::vector<bt::SE3d> truth;
  bt::PinholeCameraf camera;
};

FramePair syntheticFrames(int later) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = later + 1;
  const synth::SyntheticScene scene(settings);
  FramePair pair{{}, {}, settings.camera.cast<float>()};
  for (const int i : {0, later}) {
    const synth::SyntheticFrame f = scene.frame(i);
    pair.frames.push_back(bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, pair.camera));
    pair.truth.push_back(f.T_cam_obj);
  }
  return pair;
}

/// The GPU dense term's edge system, with every cell run through the kernel body on the host.
template <typename Loss>
bt::PairSystem denseOnHost(const bt::DensePointToPlane::Input& in, const bt::SE3d& T_i, const bt::SE3d& T_j,
                           const Loss& loss, double weight) {
  const bt::LossParameters parameters = bt::lossParameters(loss);
  const bt::DensePointToPlane gates;  // the CPU term's defaults, which the GPU term shares
  bt::PairSystem system;
  const auto pass = [&](const bt::SurfaceGrid& s, const bt::SurfaceGrid& t, const bt::SE3d& T_s, const bt::SE3d& T_t,
                        bool swapped) {
    const detail::DirectedPass p = detail::directedPass(T_s, T_t, t, gates.gate, parameters, weight);
    double sums[detail::kDenseSums] = {};
    for (const int cell : detail::surfaceCells(s))
      detail::addDenseCell(s.points.ptr<float>(), s.normals.ptr<float>(), cell, t.points.ptr<float>(),
                           t.normals.ptr<float>(), t.points.cols, t.points.rows, p, sums);
    detail::addPassSums(sums, swapped, system);
  };
  pass(in.i, in.j, T_i, T_j, false);
  pass(in.j, in.i, T_j, T_i, true);
  system.finish();
  return system;
}

template <typename Loss>
bt::PairSystem denseOnCpu(const bt::DensePointToPlane::Input& in, const bt::SE3d& T_i, const bt::SE3d& T_j,
                          const Loss& loss, double weight) {
  bt::PairSystem system;
  bt::DensePointToPlane{}.linearise(in, T_i, T_j, loss, weight, system);
  return system;
}

}  // namespace

TEST_CASE("GPU dense kernel body on the host equals the CPU dense term for every loss") {
  const auto [frames, truth, camera] = syntheticFrames(7);
  const int step = 4;
  const bt::Keyframe a = bt::makeKeyframe(0, frames[0], frames[0].mask, {}, truth[0], camera, step);
  const bt::Keyframe b = bt::makeKeyframe(7, frames[1], frames[1].mask, {}, truth[1], camera, step);
  // Poses millimetres and a degree off the truth, so that residuals reach every loss's outer branch.
  const bt::SE3d nudge =
      bt::SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.006, -0.004, 0.008, 0.01, -0.015, 0.005).finished());
  const bt::SE3d T_b = nudge * truth[1];
  const bt::DensePointToPlane::Input input{a.surface, b.surface};
  const auto compare = [&](const auto& loss) {
    const bt::PairSystem cpu = denseOnCpu(input, truth[0], T_b, loss, 0.7), host = denseOnHost(input, truth[0], T_b, loss, 0.7);
    REQUIRE(cpu.residuals > 500);
    // Same cells, same gates: only the order of double sums differs (about 1e-16 per term over
    // a few thousand terms).
    CHECK(host.residuals == cpu.residuals);
    CHECK((host.H - cpu.H).norm() <= 1e-10 * cpu.H.norm());
    CHECK((host.b - cpu.b).norm() <= 1e-10 * cpu.b.norm());
    CHECK(host.cost == doctest::Approx(cpu.cost).epsilon(1e-10));
    return cpu;
  };
  const bt::PairSystem trivial = compare(bt::TrivialLoss{});
  const bt::PairSystem huber = compare(bt::HuberLoss{});
  compare(bt::CauchyLoss{});
  compare(bt::TukeyLoss{});
  // The nudge put residuals beyond Huber's 5 mm, so its linear branch was compared too.
  CHECK(huber.cost < trivial.cost);
}

TEST_CASE("GPU rigid fit of three pairs (Horn) equals kabsch, rotations up to 180 degrees") {
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> angle(0.0, 3.14159);
  for (int trial = 0; trial < 500; ++trial) {
    CAPTURE(trial);
    Eigen::Vector3d axis(noise(random), noise(random), noise(random));
    const bt::SE3d T(bt::SO3d::exp(axis.normalized() * (trial < 20 ? 3.14159 - 1e-3 * trial : angle(random))),
                     Eigen::Vector3d(noise(random), noise(random), noise(random)) * 0.2);
    std::vector<Eigen::Vector3f> a(3), b(3);
    for (int k = 0; k < 3; ++k) {
      a[std::size_t(k)] = Eigen::Vector3f(float(noise(random)), float(noise(random)), float(noise(random))) * 0.05f;
      // Every other trial: 1 mm of noise on the moved points, so the fit is a true least-squares one.
      const Eigen::Vector3d jitter =
          Eigen::Vector3d(noise(random), noise(random), noise(random)) * (trial % 2 ? 1e-3 : 0.0);
      b[std::size_t(k)] = (T * a[std::size_t(k)].cast<double>() + jitter).cast<float>();
    }
    const bt::SE3d expected = bt::kabsch(a, b);
    const float* first[3] = {a[0].data(), a[1].data(), a[2].data()};
    const float* second[3] = {b[0].data(), b[1].data(), b[2].data()};
    double fit[12] = {};
    detail::fitRigid3(first, second, fit);
    const bt::SE3d got = detail::poseOf(fit);
    CHECK(bt::rotationGeodesic(got.rotation(), expected.rotation()) < 1e-9);
    CHECK((got.translation() - expected.translation()).norm() < 1e-9);
  }
}

TEST_CASE("GPU RANSAC trial bodies on the host draw, fit and count as the CPU trial scorer") {
  const auto [frames, truth, camera] = syntheticFrames(5);
  bt::SiftFeatures sift;
  const bt::FrameFeatures first = sift.detect(frames[0]), second = sift.detect(frames[1]);
  const auto matches = sift.match(first, second);
  REQUIRE(matches.size() > 30);
  const bt::MatchedPoints pairs(first, second, matches);
  const bt::RansacSettings settings;
  const bt::InlierGate gate(settings, bt::NoiseScale::between(first.noise_scale, second.noise_scale));
  const int trials = 300;
  std::vector<bt::SE3d> cpu_fits;
  std::vector<char> cpu_valid;
  std::vector<int> cpu_scores;
  bt::CpuTrialScorer().score(pairs, settings, gate, 0, trials, cpu_fits, cpu_valid, cpu_scores);
  std::vector<float> packed;
  detail::packPairs(pairs, packed);
  int valid = 0, exact = 0, most = 0, fewest = int(pairs.size());
  for (int b = 0; b < trials; ++b) {
    CAPTURE(b);
    double fit[12] = {};
    float hypothesis[12] = {};
    const bool ok = detail::fitTrial(packed.data(), int(pairs.size()), settings.seed, std::uint64_t(b),
                                     settings.min_sample_spread, fit, hypothesis);
    // The same samples, rejected by the same rules.
    REQUIRE(ok == bool(cpu_valid[std::size_t(b)]));
    if (!ok) continue;
    ++valid;
    const bt::SE3d& expected = cpu_fits[std::size_t(b)];
    CHECK(bt::rotationGeodesic(detail::poseOf(fit).rotation(), expected.rotation()) < 1e-9);
    CHECK((detail::poseOf(fit).translation() - expected.translation()).norm() < 1e-9);
    int inliers = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      inliers += detail::isInlier(hypothesis, packed.data() + 12 * k, gate.max_squared_distance, gate.cos_max_angle);
    // Float rounding of a distance right at the 5 mm boundary may flip one match.
    CHECK(std::abs(inliers - cpu_scores[std::size_t(b)]) <= 1);
    exact += inliers == cpu_scores[std::size_t(b)];
    most = std::max(most, inliers);
    fewest = std::min(fewest, inliers);
  }
  CHECK(valid > trials / 2);
  CHECK(exact >= valid - valid / 50);
  // Good and bad samples both occur, so the counts were compared over their whole range.
  CHECK(most > int(pairs.size()) / 2);
  CHECK(fewest < most / 4);
}

TEST_CASE("GPU two-nearest kernel distances and update on the host equals OpenCV's brute-force matcher (SIFT, ORB)") {
  const FramePair pair = syntheticFrames(5);
  const std::vector<bt::RgbdFrame>& frames = pair.frames;
  const auto check = [](const bt::FrameFeatures& a, const bt::FrameFeatures& b, auto distance) {
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(a.norm_type).knnMatch(a.descriptors, b.descriptors, knn, 2);
    REQUIRE(knn.size() == std::size_t(a.descriptors.rows));
    int same_index = 0;
    for (int q = 0; q < a.descriptors.rows; ++q) {
      bt::TwoNearest nearest;
      for (int t = 0; t < b.descriptors.rows; ++t) nearest.offer(distance(q, t), t);
      const auto& expected = knn[std::size_t(q)];
      same_index += nearest.index == expected[0].trainIdx;
      CHECK(nearest.best == doctest::Approx(expected[0].distance).epsilon(1e-5));
      CHECK(nearest.second == doctest::Approx(expected[1].distance).epsilon(1e-5));
    }
    // Indices differ only where two train rows tie to float rounding.
    CHECK(same_index >= int(0.99 * double(knn.size())));
  };
  bt::SiftFeatures sift;
  const bt::FrameFeatures sift_a = sift.detect(frames[0]), sift_b = sift.detect(frames[1]);
  REQUIRE(sift_a.size() > 100);
  const int floats = sift_a.descriptors.cols;
  check(sift_a, sift_b, [&](int q, int t) {
    return detail::L2::distance(sift_a.descriptors.ptr<float>(q), sift_b.descriptors.ptr<float>(t), floats);
  });
  bt::OrbFeatures orb;
  const bt::FrameFeatures orb_a = orb.detect(frames[0]), orb_b = orb.detect(frames[1]);
  REQUIRE(orb_a.size() > 100);
  const int words = (orb_a.descriptors.cols + 3) / 4;
  const auto words_a = detail::packWords(orb_a.descriptors, words), words_b = detail::packWords(orb_b.descriptors, words);
  check(orb_a, orb_b, [&](int q, int t) {
    return detail::Hamming::distance(words_a.data() + std::size_t(q * words), words_b.data() + std::size_t(t * words),
                                     words);
  });
}

namespace {

struct HostSolve {
  int iterations;
  Eigen::VectorXd x;
  float relative_residual;
};

/// cuda::PCG's solve with the kernel's loop run by one host thread: the same float data, packing
/// and preconditioner.
HostSolve pcgOnHost(const Eigen::MatrixXd& H, const Eigen::VectorXd& rhs, const bt::cuda::PCG& settings) {
  const int n = int(H.rows());
  const std::size_t size = static_cast<std::size_t>(n);
  std::vector<float> H_rows(size * size), block_inverse, b(size), x(size), r(size), z(size), p(size), Hp(size);
  Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(H_rows.data(), n, n) = H.cast<float>();
  for (int k = 0; k < n; ++k) b[std::size_t(k)] = float(rhs[k]);
  detail::blockJacobiInverse(H, settings.damping, block_inverse);
  HostSolve solve{0, {}, 0.0f};
  solve.iterations = detail::pcgIterations(detail::SerialTeam{}, H_rows.data(), block_inverse.data(), b.data(), x.data(),
                                           r.data(), z.data(), p.data(), Hp.data(), n, settings.max_iterations,
                                           float(settings.tolerance), &solve.relative_residual);
  solve.x = Eigen::Map<const Eigen::VectorXf>(x.data(), n).cast<double>();
  return solve;
}

}  // namespace

TEST_CASE("GPU PCG loop on the host matches the CPU PCG and converges to the dense solution") {
  // The systems and checks of the GPU test (test_cuda_pcg.cpp), with the kernel's loop on the host.
  for (const int nodes : {2, 15, 64}) {
    CAPTURE(nodes);
    Eigen::MatrixXd H;
    Eigen::VectorXd rhs, x_cpu;
    poseGraphSystem(nodes, unsigned(nodes), 1e-3, H, rhs);
    // The tracker's truncated solve: 5 iterations, against the CPU PCG stopping by the same rule
    // (the GPU's tolerance).
    const bt::cuda::PCG gpu;
    bt::PCG cpu;
    cpu.tolerance = gpu.tolerance;
    const bt::SolveReport report = cpu.solve(H, rhs, x_cpu);
    const HostSolve five = pcgOnHost(H, rhs, gpu);
    CHECK(five.iterations == report.iterations);
    CHECK((five.x - x_cpu).norm() <= 1e-4 * x_cpu.norm());
    // Run to float precision: the dense solution within what a 1e-6 residual allows.
    bt::cuda::PCG converged;
    converged.max_iterations = 2000;
    const HostSolve full = pcgOnHost(H, rhs, converged);
    const Eigen::VectorXd dense = H.ldlt().solve(rhs);
    CHECK(full.iterations < 2000);
    CHECK(full.relative_residual < 1e-5f);
    CHECK((full.x - dense).norm() <= 1e-3 * dense.norm());
  }
}
