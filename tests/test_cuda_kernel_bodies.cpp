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
#include "bundletrack/solvers/pcg.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "dense_cell.hpp"
#include "dense_host.hpp"
#include "matching_host.hpp"
#include "matching_metric.hpp"
#include "pcg_host.hpp"
#include "pcg_loop.hpp"
#include "ransac_host.hpp"
#include "ransac_pair.hpp"

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
bt::PairSystem denseOnHost(const bt::PairInput& in, const Loss& loss, double weight) {
  const bt::cuda::LossParameters parameters = bt::cuda::lossParameters(loss);
  const bt::DensePointToPlane gates;  // the CPU term's defaults, which the GPU term shares
  bt::PairSystem system;
  const auto pass = [&](const bt::Keyframe& s, const bt::Keyframe& t, const bt::SE3d& T_s, const bt::SE3d& T_t,
                        bool swapped) {
    const detail::DirectedPass p = detail::directedPass(T_s, T_t, in.grid_camera, gates.max_distance,
                                                        gates.max_normal_angle_deg, parameters, weight);
    double sums[detail::kDenseSums] = {};
    for (const int cell : detail::surfaceCells(s))
      detail::addDenseCell(s.points.ptr<float>(), s.normals.ptr<float>(), cell, t.points.ptr<float>(),
                           t.normals.ptr<float>(), t.points.cols, t.points.rows, p, sums);
    detail::addPassSums(sums, swapped, system);
  };
  pass(in.i, in.j, in.T_i, in.T_j, false);
  pass(in.j, in.i, in.T_j, in.T_i, true);
  system.finish();
  return system;
}

template <typename Loss>
bt::PairSystem denseOnCpu(const bt::PairInput& in, const Loss& loss, double weight) {
  bt::PairSystem system;
  bt::DensePointToPlane{}.linearise(in, loss, weight, system);
  return system;
}

}  // namespace

TEST_CASE("GPU dense kernel body on the host equals the CPU dense term for every loss") {
  const auto [frames, truth, camera] = syntheticFrames(7);
  const int step = 4;
  const bt::Keyframe a = bt::makeKeyframe(0, frames[0], frames[0].mask, {}, truth[0], step);
  const bt::Keyframe b = bt::makeKeyframe(7, frames[1], frames[1].mask, {}, truth[1], step);
  const bt::PinholeCameraf grid = bt::downsampledCamera(camera, step);
  // Poses millimetres and a degree off the truth, so that residuals reach every loss's outer branch.
  const bt::SE3d nudge =
      bt::SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.006, -0.004, 0.008, 0.01, -0.015, 0.005).finished());
  const bt::SE3d T_b = nudge * truth[1];
  const std::vector<bt::FeatureMatch> none;
  const bt::PairInput input{a, b, truth[0], T_b, none, grid};
  const auto compare = [&](const auto& loss) {
    const bt::PairSystem cpu = denseOnCpu(input, loss, 0.7), host = denseOnHost(input, loss, 0.7);
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

TEST_CASE("GPU RANSAC inlier test on the host counts as the CPU inlier gate") {
  const auto [frames, truth, camera] = syntheticFrames(5);
  bt::SiftFeatures sift;
  const bt::FrameFeatures first = sift.detect(frames[0]), second = sift.detect(frames[1]);
  const auto matches = sift.match(first, second);
  REQUIRE(matches.size() > 30);
  const bt::MatchedPoints pairs(first, second, matches);
  // Hypotheses around the true relative pose, from exact to far off, so counts span 0 to all.
  const bt::SE3d truth_relative = truth[1] * truth[0].inverse();
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<bt::SE3f> hypotheses;
  for (int h = 0; h < 200; ++h) {
    const double scale = 0.0005 * double(h % 40);
    Eigen::Matrix<double, 6, 1> xi;
    for (int k = 0; k < 6; ++k) xi[k] = scale * noise(random) * (k < 3 ? 1.0 : 2.0);
    hypotheses.push_back((bt::SE3d::exp(xi) * truth_relative).cast<float>());
  }
  const std::vector<char> valid(hypotheses.size(), 1);
  const bt::InlierGate gate{bt::RansacSettings{}};
  std::vector<int> cpu(hypotheses.size());
  bt::CpuInlierCounter(false).count(pairs, hypotheses, valid, gate, cpu);
  std::vector<float> packed_pairs, packed_hypotheses;
  detail::packPairs(pairs, packed_pairs);
  detail::packHypotheses(hypotheses, packed_hypotheses);
  int exact = 0, most = 0, fewest = int(pairs.size());
  for (std::size_t h = 0; h < hypotheses.size(); ++h) {
    int inliers = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      inliers += detail::isInlier(packed_hypotheses.data() + 12 * h, packed_pairs.data() + 12 * k,
                                  gate.max_squared_distance, gate.cos_max_angle);
    // Float rounding of a distance right at the 5 mm boundary may flip one match.
    CHECK(std::abs(inliers - cpu[h]) <= 1);
    exact += inliers == cpu[h];
    most = std::max(most, cpu[h]);
    fewest = std::min(fewest, cpu[h]);
  }
  CHECK(exact >= 195);
  CHECK(most > int(pairs.size()) / 2);
  CHECK(fewest < most / 4);
}

TEST_CASE("GPU two-nearest kernel body on the host equals OpenCV's brute-force matcher (SIFT, ORB)") {
  const FramePair pair = syntheticFrames(5);
  const std::vector<bt::RgbdFrame>& frames = pair.frames;
  const auto check = [](const bt::FrameFeatures& a, const bt::FrameFeatures& b, auto distance) {
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(a.norm_type).knnMatch(a.descriptors, b.descriptors, knn, 2);
    REQUIRE(knn.size() == std::size_t(a.descriptors.rows));
    int same_index = 0;
    for (int q = 0; q < a.descriptors.rows; ++q) {
      float best = INFINITY, second = INFINITY;
      int nearest = -1;
      for (int t = 0; t < b.descriptors.rows; ++t) detail::keepTwoNearest(distance(q, t), t, best, second, nearest);
      const auto& expected = knn[std::size_t(q)];
      same_index += nearest == expected[0].trainIdx;
      CHECK(best == doctest::Approx(expected[0].distance).epsilon(1e-5));
      CHECK(second == doctest::Approx(expected[1].distance).epsilon(1e-5));
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

TEST_CASE("GPU PCG loop on the host matches the CPU PCG and converges to the dense solution") {
  // A pose-graph-shaped system: 8 nodes, dense symmetric positive definite coupling.
  const int n = 48;
  const std::size_t size = n;
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  Eigen::MatrixXd M(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) M(r, c) = noise(random);
  const Eigen::MatrixXd H = M * M.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  Eigen::VectorXd rhs(n);
  for (int r = 0; r < n; ++r) rhs[r] = noise(random);
  std::vector<float> H_rows(size * size), block_inverse, b(size);
  Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(H_rows.data(), n, n) = H.cast<float>();
  for (int r = 0; r < n; ++r) b[std::size_t(r)] = float(rhs[r]);
  detail::blockJacobiInverse(H, 1e-9, block_inverse);
  std::vector<float> x(size), r(size), z(size), p(size), Hp(size);
  const auto solve = [&](int max_iterations, float tolerance, float* residual) {
    const int iterations = detail::pcgIterations(detail::SerialTeam{}, H_rows.data(), block_inverse.data(), b.data(),
                                                 x.data(), r.data(), z.data(), p.data(), Hp.data(), n, max_iterations,
                                                 tolerance, residual);
    return std::pair(iterations, Eigen::Map<const Eigen::VectorXf>(x.data(), n).cast<double>().eval());
  };
  // Five iterations, as in the tracker: the same iterate as the CPU PCG in double, up to float
  // rounding (relative 1e-7 per operation on a system of condition number about 5).
  bt::PCG cpu;
  Eigen::VectorXd x_cpu;
  const bt::SolveReport report = cpu.solve(H, rhs, x_cpu);
  float residual = 0.0f;
  const auto [iterations, x_five] = solve(cpu.max_iterations, float(cpu.tolerance), &residual);
  CHECK(iterations == report.iterations);
  CHECK((x_five - x_cpu).norm() <= 1e-4 * x_cpu.norm());
  CHECK(double(residual) == doctest::Approx(report.relative_residual).epsilon(1e-3));
  // Run to float precision: the dense solution (Eigen LDLT) within the stopping tolerance.
  const Eigen::VectorXd dense = H.ldlt().solve(rhs);
  const auto [converged_iterations, x_converged] = solve(200, 1e-6f, &residual);
  CHECK(converged_iterations < 200);
  CHECK(residual <= 1e-6f);
  CHECK((x_converged - dense).norm() <= 1e-5 * dense.norm());
}
