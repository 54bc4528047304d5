// Robust losses, residual Jacobians, linear solvers and Gauss-Newton against independent references.
#include <doctest/doctest.h>

#include <memory>
#include <random>
#include <set>
#include <span>

#include "bundletrack/energy.hpp"
#include "bundletrack/graph/keyframe_pool.hpp"
#include "bundletrack/graph/object_model.hpp"
#include "bundletrack/graph/relocalisation.hpp"
#include "bundletrack/residuals/dense_photometric.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/residuals/dense_silhouette.hpp"
#include "bundletrack/residuals/feature_point_to_point.hpp"
#include "bundletrack/solvers/dense_ldlt.hpp"
#include "bundletrack/solvers/gauss_newton.hpp"
#include "bundletrack/solvers/pcg.hpp"
#include "cost_gradient.hpp"
#include "pose_graph_fixture.hpp"
#include "pose_graph_system.hpp"

namespace bt = bundletrack;

namespace {

bt::SE3d perturbed(const bt::SE3d& T, std::mt19937& rng, double scale) {
  std::normal_distribution<double> normal(0.0, scale);
  bt::SE3d::Tangent d;
  for (int k = 0; k < 6; ++k) d[k] = normal(rng);
  return T * bt::SE3d::exp(d);
}

// A keyframe whose grid holds a curved, asymmetric surface patch z = g(x, y) = 6x^2 + 3y^2 + 20xy^2
// (object frame; no rigid motion maps it onto itself) seen from T_cam_obj, with analytic normals,
// and features at some of its points.
bt::Keyframe surfaceKeyframe(int id, const bt::SE3d& T_cam_obj, const bt::PinholeCameraf& grid) {
  bt::Keyframe k;
  k.id = id;
  k.T_cam_obj = T_cam_obj;
  k.surface.points = cv::Mat(60, 80, CV_32FC3, cv::Scalar::all(0));
  k.surface.normals = cv::Mat(60, 80, CV_32FC3, cv::Scalar::all(0));
  k.surface.camera = grid;
  // Sampled by casting each grid ray.
  const bt::SE3d T_obj_cam = T_cam_obj.inverse();
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 80; ++u) {
      const Eigen::Vector3d o = T_obj_cam.translation(), dir = T_obj_cam.rotation() * grid.unproject(u, v, 1.0f).cast<double>();
      const auto gradient = [](const Eigen::Vector3d& p) {
        return Eigen::Vector2d(12 * p.x() + 20 * p.y() * p.y(), 6 * p.y() + 40 * p.x() * p.y());
      };
      double t = 0.5;  // Newton on f(t) = z(t) - g(x(t), y(t))
      for (int it = 0; it < 30; ++it) {
        const Eigen::Vector3d p = o + t * dir;
        const double f = p.z() - (6 * p.x() * p.x() + 3 * p.y() * p.y() + 20 * p.x() * p.y() * p.y());
        t -= f / (dir.z() - gradient(p).dot(dir.head<2>()));
      }
      const Eigen::Vector3d p = o + t * dir;
      if (std::abs(p.x()) > 0.08 || std::abs(p.y()) > 0.06) continue;
      const Eigen::Vector3d n_obj = Eigen::Vector3d(-gradient(p).x(), -gradient(p).y(), 1.0).normalized();
      Eigen::Vector3d pc = T_cam_obj * p, nc = T_cam_obj.rotation() * n_obj;
      if (nc.dot(pc) > 0) nc = -nc;
      k.surface.points.at<cv::Vec3f>(v, u) = cv::Vec3f(float(pc.x()), float(pc.y()), float(pc.z()));
      k.surface.normals.at<cv::Vec3f>(v, u) = cv::Vec3f(float(nc.x()), float(nc.y()), float(nc.z()));
      if (u % 7 == 0 && v % 7 == 0) {
        k.features.points.emplace_back(pc.cast<float>());
        k.features.normals.emplace_back(nc.cast<float>());
      }
    }
  }
  bt::indexCells(k.surface);
  // Brightness linear in the pixel, so that bilinear sampling is exact and its derivatives are the
  // image's: the residual's dependence on the poses is then all in the projection.
  k.image.box = cv::Rect(0, 0, 80, 60);
  k.image.samples.create(60, 80, CV_32FC3);
  for (int v = 0; v < 60; ++v)
    for (int u = 0; u < 80; ++u)
      k.image.samples.at<cv::Vec3f>(v, u) = {0.3f + 0.004f * float(u) + 0.003f * float(v) + 0.01f * float(id), 0.004f, 0.003f};
  k.image.valid = cv::Mat(60, 80, CV_8UC1, cv::Scalar(255));
  k.image.sampleCells(k.surface);
  // A signed distance likewise linear and positive (every point lands outside the silhouette),
  // seen past by a far background: every point counts.
  k.silhouette.box = k.image.box;
  k.silhouette.samples.create(60, 80, CV_32FC3);
  for (int v = 0; v < 60; ++v)
    for (int u = 0; u < 80; ++u)
      k.silhouette.samples.at<cv::Vec3f>(v, u) = {1.0f + 0.05f * float(u) - 0.02f * float(v) + 0.1f * float(id), 0.05f, -0.02f};
  k.silhouette.depth = cv::Mat(60, 80, CV_32FC1, cv::Scalar(10.0));
  for (const cv::Point& cell : k.surface.cells) k.silhouette.points.push_back(k.surface.points.at<cv::Vec3f>(cell));
  return k;
}

/// Four views of the patch, each turned and moved a little from the one before.
std::vector<bt::SE3d> fourViews() {
  std::vector<bt::SE3d> views;
  for (int k = 0; k < 4; ++k)
    views.emplace_back(bt::SO3d::exp(Eigen::Vector3d(2.8 + 0.05 * k, 0.04 * k, -0.03 * k)),
                       Eigen::Vector3d(0.01 * k, -0.005 * k, 0.6 + 0.01 * k));
  return views;
}

/// Keyframes of the patch seen from `views`, on a 150 px grid camera.
std::vector<bt::Keyframe> patchKeyframes(const std::vector<bt::SE3d>& views) {
  const bt::PinholeCameraf grid{150.0f, 150.0f, 39.5f, 29.5f};
  std::vector<bt::Keyframe> frames;
  for (std::size_t k = 0; k < views.size(); ++k) frames.push_back(surfaceKeyframe(int(k), views[k], grid));
  return frames;
}

/// The CPU dense term behind the batch interface, recording the size of every batch it is given.
struct BatchedDense {
  bt::DensePointToPlane dense;
  std::shared_ptr<std::vector<std::size_t>> batches = std::make_shared<std::vector<std::size_t>>();

  using Input = bt::DensePointToPlane::Input;
  static Input input(const bt::EdgeView& edge) { return bt::DensePointToPlane::input(edge); }

  template <bt::RobustLoss Loss>
  void linearise(const Input& in, const bt::SE3d& T_i, const bt::SE3d& T_j, const Loss& loss, double weight,
                 bt::PairSystem& system) const {
    dense.linearise(in, T_i, T_j, loss, weight, system);
  }
  template <bt::RobustLoss Loss>
  void lineariseAll(std::span<const Input> inputs, std::span<const bt::GraphEdge> edges, std::span<const bt::SE3d> poses,
                    const Loss& loss, double weight, std::span<bt::PairSystem> systems) const {
    batches->push_back(inputs.size());
    for (std::size_t e = 0; e < inputs.size(); ++e)
      dense.linearise(inputs[e], poses[std::size_t(edges[e].i)], poses[std::size_t(edges[e].j)], loss, weight, systems[e]);
  }
};
static_assert(bt::BatchResidual<BatchedDense>);
static_assert(!bt::BatchResidual<bt::DensePointToPlane>);

}  // namespace

TEST_CASE_TEMPLATE("robust losses match their formulas and rho' is the derivative of rho", Loss, bt::TrivialLoss,
                   bt::HuberLoss, bt::CauchyLoss, bt::TukeyLoss) {
  const Loss loss;
  for (const double r : {0.0005, 0.003, 0.0049, 0.0051, 0.008, 0.02, 0.1}) {
    const double s = r * r, h = 1e-9;
    const bt::LossValue value = loss.evaluate(s);
    CAPTURE(r);
    CHECK(value.d_rho == doctest::Approx((loss.evaluate(s + h).rho - loss.evaluate(s - h).rho) / (2 * h)).epsilon(1e-5));
    CHECK(value.dd_rho ==
          doctest::Approx((loss.evaluate(s + h).d_rho - loss.evaluate(s - h).d_rho) / (2 * h)).epsilon(1e-4).scale(1e3));
  }
  // The weights themselves, by hand: Huber (delta 5 mm) weighs 1 inside, delta / |r| outside.
  CHECK(bt::HuberLoss{}.evaluate(0.004 * 0.004).d_rho == 1.0);
  CHECK(bt::HuberLoss{}.evaluate(0.01 * 0.01).d_rho == doctest::Approx(0.5));
  CHECK(bt::CauchyLoss{}.evaluate(0.005 * 0.005).d_rho == doctest::Approx(0.5));  // 1 / (1 + s / c^2) at s = c^2
  CHECK(bt::TukeyLoss{}.evaluate(0.005 * 0.005).d_rho == doctest::Approx(0.5625));  // (1 - 1/4)^2 at |r| = c / 2
  CHECK(bt::TukeyLoss{}.evaluate(0.02 * 0.02).d_rho == 0.0);
}

TEST_CASE("feature, dense, photometric and silhouette residual Jacobians equal central differences of the residuals") {
  std::mt19937 rng(3);
  const bt::PinholeCameraf grid{150.0f, 150.0f, 39.5f, 29.5f};
  const bt::SE3d T_i(bt::SO3d::exp(Eigen::Vector3d(2.8, 0.1, 0.0)), Eigen::Vector3d(0.0, 0.0, 0.6));
  const bt::SE3d T_j = T_i * bt::SE3d::exp((bt::SE3d::Tangent() << 0.01, -0.005, 0.0, 0.03, -0.02, 0.05).finished());
  const bt::Keyframe ki = surfaceKeyframe(0, T_i, grid), kj = surfaceKeyframe(1, T_j, grid);
  // Feature correspondences: the same object point seen by both (matched by nearest object point).
  std::vector<bt::FeatureMatch> matches;
  for (int a = 0; a < int(ki.features.points.size()); ++a) {
    const Eigen::Vector3d pa = T_i.inverse() * ki.features.points[a].cast<double>();
    int best = 0;
    for (int b = 0; b < int(kj.features.points.size()); ++b)
      if ((T_j.inverse() * kj.features.points[b].cast<double>() - pa).norm() <
          (T_j.inverse() * kj.features.points[best].cast<double>() - pa).norm())
        best = b;
    matches.push_back({a, best});
  }
  // Evaluated slightly off the true poses so that residuals are non-zero.
  const bt::SE3d Ti = perturbed(T_i, rng, 0.002), Tj = perturbed(T_j, rng, 0.002);
  // The trivial loss makes H = J^T J and b = J^T r, so finite differences of the total cost
  // 1/2 sum r^2 must equal b, and H must be the Gauss-Newton matrix of the differenced residuals.
  const auto check = [&](const auto& residual) {
    using R = std::decay_t<decltype(residual)>;
    const auto cost = [&](const bt::SE3d& A, const bt::SE3d& B) {
      bt::PairSystem system;
      residual.linearise(R::input(bt::EdgeView{ki, kj, matches}), A, B, bt::TrivialLoss{}, 1.0, system);
      return system;
    };
    const bt::PairSystem at = cost(Ti, Tj);
    REQUIRE(at.residuals > 20);
    // A tiny step: projective association rounds to grid cells, and a step that moves a projection
    // across a cell boundary changes the residual set (expected flips ~ points x step x f / z).
    const Eigen::Matrix<double, 12, 1> gradient =
        halfCostGradient([&](const bt::SE3d& A, const bt::SE3d& B) { return cost(A, B).cost; }, Ti, Tj, 1e-8);
    CAPTURE(gradient.transpose());
    CAPTURE(at.b.transpose());
    CHECK((gradient - at.b).norm() <= 1e-5 * at.b.norm() + 1e-12);
    CHECK((at.H - at.H.transpose()).norm() < 1e-12 * at.H.norm());
  };
  check(bt::FeaturePointToPoint{});
  check(bt::DensePointToPlane{});
  check(bt::DensePhotometric{});
  // The silhouette term's weight follows how far a point's depth error moves it across the outline,
  // which changes with the poses as a robust weight does and is held fixed in a step as one is;
  // with a wide outline spread it is constant to 1e-9, and the differences test the Jacobian alone.
  bt::DenseSilhouette silhouette;
  silhouette.sigma = 1e3;
  check(silhouette);
}

TEST_CASE("PCG and dense LDLT give the same update on a pose-graph system") {
  Eigen::MatrixXd H;
  Eigen::VectorXd rhs;
  poseGraphSystem(12, 4, 1e-6, H, rhs);
  const auto [report, error] = solveAgainstDense(bt::PCG{}, 500, 1e-12, H, rhs);
  CHECK(report.relative_residual < 1e-10);
  CHECK(error <= 1e-6);
  // The truncated default (5 iterations) is an approximation: it reduces the residual but stops.
  Eigen::VectorXd x_short;
  const bt::SolveReport short_report = bt::PCG{}.solve(H, rhs, x_short);
  CHECK(short_report.iterations == 5);
  CHECK(short_report.relative_residual < 1.0);
}

TEST_CASE("Gauss-Newton brings perturbed poses back to the truth, node 0 fixed, with and without step control") {
  std::mt19937 rng(5);
  const std::vector<bt::SE3d> truth = fourViews();
  const std::vector<bt::Keyframe> frames = patchKeyframes(truth);
  // Features correspond by index (the same grid cells see nearby, not identical, points), so only
  // the dense term is used here; it is exact up to the grid's sampling.
  const std::vector<bt::FeatureMatch> none;
  std::vector<bt::SE3d> start = truth;
  for (int k = 1; k < 4; ++k) start[k] = perturbed(truth[k], rng, 0.004);
  const bt::PoseGraph graph = allPairsGraph(frames, start, none);
  const bt::Energy<bt::Term<bt::DensePointToPlane, bt::HuberLoss>> dense_only;
  for (const bt::StepControl control : {bt::StepControl::None, bt::StepControl::LevenbergMarquardt}) {
    CAPTURE(int(control));
    bt::GaussNewtonSettings settings;
    settings.iterations = 15;
    settings.step_control = control;
    std::vector<bt::SE3d> poses = start;
    const auto report = bt::optimizePoseGraph(dense_only.over(graph), bt::DenseLDLT{}, poses, settings);
    CHECK(report.final_cost < report.initial_cost);
    // Every step is solved and reported; plain Gauss-Newton takes each one.
    CHECK(int(report.solves.size()) == report.iterations + report.rejected_steps);
    if (control == bt::StepControl::None) CHECK(report.rejected_steps == 0);
    // The energy of the result, evaluated afresh, is the last one reported (Levenberg-Marquardt
    // keeps the linearisation of an accepted step).
    bt::Linearisation at_result;
    bt::assembleNormalEquations(dense_only.over(graph), poses, at_result);
    if (control == bt::StepControl::LevenbergMarquardt)
      CHECK(at_result.cost == doctest::Approx(report.final_cost).epsilon(1e-12));
    CHECK((poses[0].matrix() - truth[0].matrix()).norm() == 0.0);
    for (int k = 1; k < 4; ++k) {
      CAPTURE(k);
      // A paraboloid constrains all six degrees of freedom; residual error comes from the 4 mm grid.
      CHECK((poses[k].translation() - truth[k].translation()).norm() < 1e-3);
      CHECK(bt::rotationGeodesic(poses[k].rotation(), truth[k].rotation()) * 180.0 / 3.14159 < 0.2);
    }
  }
}

TEST_CASE("a batch residual gets every edge of the graph in one call and adds what the edge-wise term adds") {
  std::mt19937 rng(11);
  const bt::PinholeCameraf grid{150.0f, 150.0f, 39.5f, 29.5f};
  std::vector<bt::Keyframe> frames;
  std::vector<bt::SE3d> poses;
  for (const bt::SE3d& T : fourViews()) {
    frames.push_back(surfaceKeyframe(int(frames.size()), T, grid));
    poses.push_back(frames.size() == 1 ? T : perturbed(T, rng, 0.003));
  }
  // Features "correspond" by index, as far as every frame has one: the feature term only has to
  // contribute, not to be right.
  std::size_t common = frames[0].features.size();
  for (const auto& f : frames) common = std::min(common, f.features.size());
  std::vector<bt::FeatureMatch> matches;
  for (int f = 0; f < int(common); ++f) matches.push_back({f, f});
  const bt::PoseGraph graph = allPairsGraph(frames, poses, matches);
  const bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>, bt::Term<bt::DensePointToPlane, bt::HuberLoss>> edge_wise;
  const bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>, bt::Term<BatchedDense, bt::HuberLoss>> batched;
  bt::Linearisation by_edge, by_batch;
  bt::assembleNormalEquations(edge_wise.over(graph), poses, by_edge);
  bt::assembleNormalEquations(batched.over(graph), poses, by_batch);
  REQUIRE(by_edge.residuals > 1000);
  // Per edge the terms add in the same order, so the sums are the same to the last bit.
  CHECK(by_batch.residuals == by_edge.residuals);
  CHECK(by_batch.cost == by_edge.cost);
  CHECK(by_batch.H == by_edge.H);
  CHECK(by_batch.b == by_edge.b);
  const auto& batches = *std::get<1>(batched.terms).residual.batches;
  REQUIRE(batches.size() == 1);
  CHECK(batches[0] == graph.edges.size());
  // Serial and parallel linearisation give the same system, bit for bit.
  bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>, bt::Term<bt::DensePointToPlane, bt::HuberLoss>> serial;
  serial.execution = bt::Execution::Serial;
  bt::Linearisation one_thread;
  bt::assembleNormalEquations(serial.over(graph), poses, one_thread);
  CHECK(one_thread.H == by_edge.H);
  CHECK(one_thread.b == by_edge.b);
  CHECK(one_thread.cost == by_edge.cost);
}

TEST_CASE("a kept edge system moved along its linear model equals the system of the linear residual at the new poses") {
  // Residuals exactly linear in the right perturbations, r(d) = r0 + J d, made into a system at
  // d = 0 and, independently, at d: the kept one moved by d must be the latter up to rounding.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::Vector3d> r0(20);
  std::vector<Eigen::Matrix<double, 3, 12>> J(20);
  for (std::size_t k = 0; k < r0.size(); ++k) {
    r0[k] = Eigen::Vector3d::NullaryExpr([&] { return 0.01 * normal(rng); });
    J[k] = Eigen::Matrix<double, 3, 12>::NullaryExpr([&] { return normal(rng); });
  }
  const auto systemAt = [&](const Eigen::Matrix<double, 12, 1>& d) {
    bt::PairSystem system;
    for (std::size_t k = 0; k < r0.size(); ++k)
      system.add<3>(r0[k] + J[k] * d, J[k].leftCols<6>(), J[k].rightCols<6>(), bt::TrivialLoss{}, 1.0);
    return system;
  };
  const bt::SE3d T_a = perturbed(bt::SE3d{}, rng, 0.3), T_b = perturbed(bt::SE3d{}, rng, 0.3);
  bt::EdgeLinearisationCache cache({.max_translation = 1e-3, .max_rotation = 2e-3});
  REQUIRE(cache.enabled());
  cache.keep(4, 9, T_a, T_b, systemAt(Eigen::Matrix<double, 12, 1>::Zero()));
  Eigen::Matrix<double, 12, 1> d;
  d << 3e-4, -2e-4, 1e-4, 5e-4, -8e-4, 2e-4, -1e-4, 4e-4, 2e-4, -3e-4, 1e-4, 6e-4;
  bt::PairSystem moved;
  REQUIRE(cache.reuse(4, 9, T_a * bt::SE3d::exp(d.head<6>()), T_b * bt::SE3d::exp(d.tail<6>()), moved));
  const bt::PairSystem fresh = systemAt(d);
  CHECK(moved.H == fresh.H);
  CHECK((moved.b - fresh.b).norm() < 1e-12 * fresh.b.norm());
  CHECK(moved.cost == doctest::Approx(fresh.cost).epsilon(1e-12));
  CHECK(moved.residuals == fresh.residuals);
  // Farther than the settings allow, in either pose, or another pair, or a forgotten keyframe: none.
  bt::SE3d::Tangent far = bt::SE3d::Tangent::Zero();
  far[0] = 1.1e-3;
  CHECK_FALSE(cache.reuse(4, 9, T_a * bt::SE3d::exp(far), T_b, moved));
  far << 0, 0, 0, 0, 0, 2.1e-3;
  CHECK_FALSE(cache.reuse(4, 9, T_a, T_b * bt::SE3d::exp(far), moved));
  CHECK_FALSE(cache.reuse(9, 4, T_b, T_a, moved));
  CHECK(cache.reuse(4, 9, T_a, T_b, moved));
  cache.forget(9);
  CHECK_FALSE(cache.reuse(4, 9, T_a, T_b, moved));
  CHECK_FALSE(bt::EdgeLinearisationCache().enabled());
}

TEST_CASE("lazy relinearisation: edges between pool keyframes are linearised again only when a keyframe has moved") {
  std::mt19937 rng(5);
  const std::vector<bt::SE3d> truth = fourViews();
  const std::vector<bt::Keyframe> frames = patchKeyframes(truth);
  const std::vector<bt::FeatureMatch> none;
  std::vector<bt::SE3d> start = truth;
  for (int k = 1; k < 4; ++k) start[k] = perturbed(truth[k], rng, k < 3 ? 2e-4 : 0.004);  // keyframes settled, the frame not
  bt::PoseGraph graph = allPairsGraph(frames, start, none);
  graph.pool_indices = {0, 1, 2};  // nodes 0-2 are the pool's keyframes, node 3 the current frame
  const bt::Energy<bt::Term<BatchedDense, bt::HuberLoss>> energy;
  std::vector<std::size_t>& batches = *std::get<0>(energy.terms).residual.batches;
  bt::GaussNewtonSettings settings;
  settings.iterations = 10;
  settings.min_translation_step = settings.min_rotation_step = 0.0;  // every step, so that both runs take as many
  std::vector<bt::SE3d> every_step = start;
  bt::optimizePoseGraph(energy.over(graph), bt::DenseLDLT{}, every_step, settings);
  REQUIRE(batches.size() == 10);
  for (const std::size_t edges : batches) CHECK(edges == 6);
  batches.clear();
  // The tracker's settings: a keyframe relinearises its edges after moving 0.5 mm or turning 1 mrad.
  bt::EdgeLinearisationCache kept({.max_translation = 5e-4, .max_rotation = 1e-3});
  std::vector<bt::SE3d> lazy = start;
  bt::optimizePoseGraph(energy.over(graph, &kept), bt::DenseLDLT{}, lazy, settings);
  REQUIRE(batches.size() == 10);
  CHECK(batches[0] == 6);
  std::size_t linearised = 0;
  for (const std::size_t edges : batches) linearised += edges;
  MESSAGE("edges linearised in 10 steps: " << linearised << " lazily, 60 every step");
  CHECK(linearised < 60 * 3 / 4);
  // The kept systems pair points as the poses they were made at did (the keyframes start 0.35 mm
  // from the truth): on this coarse grid (4 mm cells) that moves the minimum by less than the
  // sampling error every-step relinearisation itself leaves (up to 65 um and 0.5 mrad here).
  // Kept systems left where they were made (no b + H d) hold the keyframes at their start instead.
  for (int k = 1; k < 4; ++k) {
    CAPTURE(k);
    const double moved = (lazy[k].translation() - every_step[k].translation()).norm();
    const double turned = bt::rotationGeodesic(lazy[k].rotation(), every_step[k].rotation());
    MESSAGE("node " << k << ": lazy vs every step " << moved * 1e6 << " um, " << turned * 1e3 << " mrad; every step vs truth "
                     << (every_step[k].translation() - truth[k].translation()).norm() * 1e6 << " um, "
                     << bt::rotationGeodesic(every_step[k].rotation(), truth[k].rotation()) * 1e3 << " mrad; lazy vs truth "
                     << (lazy[k].translation() - truth[k].translation()).norm() * 1e6 << " um, "
                     << bt::rotationGeodesic(lazy[k].rotation(), truth[k].rotation()) * 1e3 << " mrad");
    CHECK(moved < 5e-5);
    CHECK(turned < 5e-4);
    CHECK((lazy[k].translation() - truth[k].translation()).norm() < 1e-4);
    CHECK(bt::rotationGeodesic(lazy[k].rotation(), truth[k].rotation()) < 1e-3);
  }
  // A second optimisation from the result reuses every keyframe edge: no keyframe moves far.
  batches.clear();
  std::vector<bt::SE3d> again = lazy;
  bt::optimizePoseGraph(energy.over(graph, &kept), bt::DenseLDLT{}, again, settings);
  for (const std::size_t edges : batches) CHECK(edges == 3);
}

TEST_CASE("keyframe pool: greedy selection keeps frame 0 and follows the geodesic sums, and the pool is bounded") {
  bt::KeyframePool pool(4);
  const Eigen::Vector3d rotations[4] = {{0, 0, 0}, {0.5, 0, 0}, {0, 0, 0.5}, {0, 0, 0.2}};
  for (int k = 0; k < 4; ++k) {
    bt::Keyframe f;
    f.id = k;
    f.T_cam_obj = bt::SE3d(bt::SO3d::exp(rotations[k]), Eigen::Vector3d::Zero());
    pool.add(f);
  }
  // Current: 0.3 rad about z. Sums to {current, frame 0}: id1 0.58 + 0.5, id2 0.2 + 0.5, id3 0.1 + 0.2
  // -> id3; adding the distance to id3: id1 1.08 + 0.54, id2 0.7 + 0.3 -> id2.
  const auto chosen = pool.select(bt::SO3d::exp(Eigen::Vector3d(0, 0, 0.3)), 3);
  REQUIRE(chosen.size() == 3);
  CHECK(pool[chosen[0]].id == 0);
  CHECK(pool[chosen[1]].id == 3);
  CHECK(pool[chosen[2]].id == 2);
  CHECK(pool.select(bt::SO3d(), 10).size() == 4);
  const double ten_degrees = 10.0 * 3.141592653589793 / 180.0;
  CHECK(pool.isNovelView(bt::SO3d::exp(Eigen::Vector3d(0, 0, 1.2)), ten_degrees));
  CHECK_FALSE(pool.isNovelView(bt::SO3d::exp(Eigen::Vector3d(0, 0, 0.62)), ten_degrees));
  // Full: the most redundant keyframe goes (id 3, 0.2 rad from frame 0), never frame 0 itself.
  bt::Keyframe extra;
  extra.id = 9;
  extra.T_cam_obj = bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0, 0, 2.0)), Eigen::Vector3d::Zero());
  CHECK(pool.add(extra) == 3);
  CHECK(pool.size() == 4);
  CHECK(pool[0].id == 0);
}

TEST_CASE("re-acquisition starts: turned about the object's centre by each ring, and the largest consensus") {
  const bt::SE3d pose(bt::SO3d::exp(Eigen::Vector3d(0.1, -0.3, 0.2)), Eigen::Vector3d(0.1, 0.0, 2.0));
  const Eigen::Vector3d pivot(0.12, 0.05, 2.1);
  const double step = 20.0 * 3.141592653589793 / 180.0;
  const std::vector<bt::SE3d> starts = bt::turnedAbout(pose, pivot, step, 2);
  REQUIRE(starts.size() == 12);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const double ring = k < 6 ? 1.0 : 2.0;
    // Turned by ring * step relative to the pose, about a camera axis, the pivot kept in place.
    const bt::SO3d turn = starts[k].rotation() * pose.rotation().inverse();
    CHECK(bt::rotationGeodesic(starts[k].rotation(), pose.rotation()) == doctest::Approx(ring * step).epsilon(1e-12));
    CHECK(turn.log().normalized().cwiseAbs().maxCoeff() == doctest::Approx(1.0).epsilon(1e-12));
    const Eigen::Vector3d pivot_in_object = pose.inverse() * pivot;
    CHECK((starts[k] * pivot_in_object - pivot).norm() < 1e-12);
  }
  CHECK(bt::turnedAbout(pose, pivot, step, 0).empty());

  // Three poses within 1 degree and 5 mm of the second, two far from them and from each other.
  const auto nudged = [&](double angle_deg, double metres) {
    return bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0, 0, angle_deg * 3.141592653589793 / 180.0)),
                    Eigen::Vector3d(metres, 0, 0)) * pose;
  };
  const std::vector<bt::SE3d> reached = {nudged(90, 0.0), nudged(0.5, 0.002), nudged(-0.4, 0.0), nudged(0.9, -0.002),
                                         nudged(45, 0.1)};
  const double two_degrees = 2.0 * 3.141592653589793 / 180.0;
  const std::vector<std::size_t> group = bt::largestConsensus(reached, two_degrees, 0.005);
  REQUIRE(group.size() == 3);
  CHECK(group[0] == 1);  // the first member whose neighbourhood holds the others
  CHECK(std::set<std::size_t>(group.begin(), group.end()) == std::set<std::size_t>{1, 2, 3});
  CHECK(bt::largestConsensus({}, two_degrees, 0.005).empty());
  CHECK(bt::largestConsensus(reached, two_degrees, 0.001).size() == 1);  // 2 mm apart: none agree
}

TEST_CASE("object model: keyframes' points averaged in the object frame, points one keyframe saw alone dropped") {
  // A 5x5 patch of the plane z = 2 mm (object frame), 1 cm apart, mid-voxel for 4 mm voxels; seen by
  // two keyframes at different poses, red in the first and blue in the second; the first also
  // sees a background point.
  const bt::SE3d poses[2] = {bt::SE3d(bt::SO3d(), Eigen::Vector3d(0, 0, 1.0)),
                             bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0.35, 0, 0)), Eigen::Vector3d(0.01, 0, 1.1))};
  const cv::Vec3b colors[2] = {{0, 0, 200}, {100, 0, 0}};
  bt::KeyframePool pool(4);
  for (int k = 0; k < 2; ++k) {
    bt::Keyframe keyframe;
    keyframe.id = k;
    keyframe.T_cam_obj = poses[k];
    bt::SurfaceGrid& grid = keyframe.surface;
    grid.camera = {100.0f, 100.0f, 5.0f, 5.0f};
    grid.points = cv::Mat::zeros(6, 6, CV_32FC3);
    grid.normals = cv::Mat::zeros(6, 6, CV_32FC3);
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 5; ++j) {
        const Eigen::Vector3f p = (poses[k] * Eigen::Vector3d(0.01 * i + 0.001, 0.01 * j + 0.001, 0.002)).cast<float>();
        const Eigen::Vector3f n = (poses[k].rotation() * Eigen::Vector3d(0, 0, -1)).cast<float>();
        grid.points.at<cv::Vec3f>(j, i) = {p.x(), p.y(), p.z()};
        grid.normals.at<cv::Vec3f>(j, i) = {n.x(), n.y(), n.z()};
      }
    if (k == 0) {
      grid.points.at<cv::Vec3f>(5, 5) = {0.3f, 0.3f, 1.5f};
      grid.normals.at<cv::Vec3f>(5, 5) = {0.0f, 0.0f, -1.0f};
    }
    bt::indexCells(grid);
    grid.colors.assign(grid.cells.size(), colors[k]);
    pool.add(keyframe);
  }
  const std::vector<bt::ModelPoint> model = bt::fuseObjectModel(pool, {0.004f, 2});
  REQUIRE(model.size() == 25);
  for (const bt::ModelPoint& p : model) {
    CHECK(p.position.z() == doctest::Approx(0.002).epsilon(1e-5));
    CHECK((p.normal - Eigen::Vector3f(0, 0, -1)).norm() < 1e-5);
    CHECK(p.color == cv::Vec3b(50, 0, 100));  // the mean of both keyframes' colours
  }
  CHECK(bt::fuseObjectModel(pool, {0.004f, 1}).size() == 26);  // with the background point
}
