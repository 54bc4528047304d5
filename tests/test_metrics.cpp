// Pose metrics against values computed by hand and brute force.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "bundletrack/eval/score_table.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/viz/overlay.hpp"

namespace bt = bundletrack;

TEST_CASE("AUC follows the YCB-Video VOCap definition on hand-computed cases") {
  // errors 1 cm, 2 cm, 20 cm: accuracy 1/3 on (0, 1 cm], 2/3 on (1 cm, 10 cm], the 20 cm never counts.
  // Area = 0.01/3 + 0.01*2/3 + 0.08*2/3 = 0.06333 of 0.1.
  CHECK(bt::areaUnderCurve({0.02, 0.2, 0.01}) == doctest::Approx(63.3333).epsilon(1e-6));
  CHECK(bt::areaUnderCurve({0.2, 0.15, 0.3}) == 0.0);  // all above the threshold
  CHECK(bt::areaUnderCurve({}) == 0.0);
  CHECK(bt::areaUnderCurve({0.0, 0.0}) == doctest::Approx(100.0));  // perfect
  // Ties: both at 5 cm. VOCap takes the precision 1/2 on (0, 5 cm] and 1 on (5, 10 cm]: 75.
  CHECK(bt::areaUnderCurve({0.05, 0.05}) == doctest::Approx(75.0));
}

TEST_CASE("ADD, ADD-S and pose errors on a symmetric model") {
  // A ring of points around the z axis: symmetric under rotations about z by multiples of 30 deg.
  std::vector<Eigen::Vector3f> ring;
  for (int k = 0; k < 12; ++k) {
    const double a = k * 3.141592653589793 / 6.0;
    ring.emplace_back(float(0.05 * std::cos(a)), float(0.05 * std::sin(a)), 0.0f);
  }
  const bt::KdTree3 tree(ring);
  const bt::SE3d truth(bt::SO3d::exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(0.0, 0.0, 0.7));
  const bt::SE3d shifted(truth.rotation(), truth.translation() + Eigen::Vector3d(0.003, 0.0, 0.004));
  CHECK(bt::averageDistance(ring, truth, shifted) == doctest::Approx(0.005).epsilon(1e-5));
  CHECK(bt::translationError(truth, shifted) == doctest::Approx(0.005));
  const bt::SE3d turned = truth * bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0, 0, 3.141592653589793 / 6.0)), {0, 0, 0});
  CHECK(bt::averageDistanceSymmetric(ring, tree, truth, turned) < 1e-6);
  // ADD sees the 30 degree turn: each point moves by the chord 2 r sin(15 deg).
  CHECK(bt::averageDistance(ring, truth, turned) == doctest::Approx(2 * 0.05 * std::sin(3.141592653589793 / 12)).epsilon(1e-5));
  CHECK(bt::rotationErrorDeg(truth, turned) == doctest::Approx(30.0));
}

TEST_CASE("k-d tree nearest neighbour equals brute force, near the cloud and far from it") {
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  std::vector<Eigen::Vector3f> points(3000);
  for (auto& p : points) p = Eigen::Vector3f(u(rng), u(rng), u(rng));
  const bt::KdTree3 tree(points);
  for (int q = 0; q < 600; ++q) {
    // Half the queries within 1.5 times the cloud, half up to 2 m away (a wrong pose scored).
    const float reach = q < 300 ? 1.5f : 20.0f;
    const Eigen::Vector3f query(u(rng) * reach, u(rng) * reach, u(rng) * reach);
    float best = std::numeric_limits<float>::max();
    for (const auto& p : points) best = std::min(best, (p - query).squaredNorm());
    REQUIRE(tree.nearestSquaredDistance(query) == best);
  }
}

TEST_CASE("a large model is scored on a strided subsample whose ADD-S stays within the stated bound") {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  std::vector<Eigen::Vector3f> model(3000);
  for (auto& p : model) p = Eigen::Vector3f(u(rng), u(rng), 0.5f * u(rng));
  const bt::ScoringSubsample subsample = bt::scoringSubsample(model, 500);
  CHECK(subsample.stride == 6);
  REQUIRE(subsample.points.size() == 500);
  CHECK(subsample.points[7] == model[42]);
  // The bound: the farthest any model point lies from the subsample, by brute force.
  double farthest = 0.0;
  for (const auto& p : model) {
    float nearest = std::numeric_limits<float>::max();
    for (const auto& q : subsample.points) nearest = std::min(nearest, (p - q).squaredNorm());
    farthest = std::max(farthest, std::sqrt(double(nearest)));
  }
  CHECK(subsample.bound == doctest::Approx(farthest).epsilon(1e-6));
  // Per point the subsample's ADD-S distance lies in [whole model's, whole model's + bound], so does the mean.
  const bt::SE3d truth(bt::SO3d::exp(Eigen::Vector3d(0.3, 0.1, -0.2)), Eigen::Vector3d(0.0, 0.0, 0.9));
  const bt::SE3d estimate(truth.rotation() * bt::SO3d::exp(Eigen::Vector3d(0.0, 0.1, 0.0)),
                          truth.translation() + Eigen::Vector3d(0.01, 0.0, 0.0));
  const double whole = bt::averageDistanceSymmetric(subsample.points, bt::KdTree3(model), truth, estimate);
  const double sub = bt::averageDistanceSymmetric(subsample.points, bt::KdTree3(subsample.points), truth, estimate);
  CHECK(sub >= whole);
  CHECK(sub <= whole + subsample.bound);
  // A model within the limit is scored whole.
  CHECK(bt::scoringSubsample(model, 3000).points.size() == 3000);
  CHECK(bt::scoringSubsample(model, 3000).bound == 0.0);
  // scoreSequence says what it scored on.
  std::vector<Eigen::Vector3f> large(bt::kMostScoredPoints * 2, Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < large.size(); ++i) large[i] = Eigen::Vector3f(u(rng), u(rng), u(rng));
  const bt::SequenceScore score = bt::scoreSequence(large, {truth}, std::vector<bt::SE3d>{estimate});
  CHECK(score.model_points == large.size());
  CHECK(score.scored_points == bt::kMostScoredPoints);
  CHECK(score.subsample_bound_cm > 0.0);
  CHECK(bt::formatScoreTable({{"s", score}}).find("on 50000 of the model's 100000 points") != std::string::npos);
}

TEST_CASE("oriented box IoU on hand-computed configurations") {
  const bt::ObjectBox cube{Eigen::Vector3d(-0.05, -0.05, -0.05), Eigen::Vector3d(0.05, 0.05, 0.05)};
  const bt::SE3d A(bt::SO3d::exp(Eigen::Vector3d(0.3, -0.2, 0.1)), Eigen::Vector3d(0.1, 0.0, 0.7));
  CHECK(bt::boxIoU(cube, A, A) == doctest::Approx(1.0).epsilon(1e-9));
  // Shifted by half its side along its own x: intersection V/2, union 3V/2.
  CHECK(bt::boxIoU(cube, A, A * bt::SE3d(bt::SO3d(), Eigen::Vector3d(0.05, 0, 0))) == doctest::Approx(1.0 / 3.0).epsilon(0.01));
  // A cube turned by 90 degrees about an axis is itself.
  CHECK(bt::boxIoU(cube, A, A * bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0, 0, 1.5707963267948966)), {0, 0, 0})) ==
        doctest::Approx(1.0).epsilon(0.01));
  // Turned by 45 degrees about z: the intersection is a regular octagon prism, area 2 (sqrt 2 - 1) s^2
  // of the square's s^2 = 0.8284 V; IoU = 0.8284 / (2 - 0.8284) = 0.7071.
  CHECK(bt::boxIoU(cube, A, A * bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0, 0, 0.7853981633974483)), {0, 0, 0})) ==
        doctest::Approx(0.7071).epsilon(0.01));
  CHECK(bt::boxIoU(cube, A, A * bt::SE3d(bt::SO3d(), Eigen::Vector3d(0.2, 0, 0))) == 0.0);
}

TEST_CASE("frames without an estimate count as failures") {
  std::vector<Eigen::Vector3f> model = {{0.05f, 0, 0}, {0, 0.05f, 0}, {0, 0, 0.05f}, {-0.05f, 0, 0}};
  const bt::SE3d T(bt::SO3d(), Eigen::Vector3d(0, 0, 0.7));
  const std::vector<bt::SE3d> truth(4, T);
  const std::vector<std::optional<bt::SE3d>> estimate = {T, std::nullopt, T, std::nullopt};
  const bt::SequenceScore score = bt::scoreSequence(model, truth, estimate);
  CHECK(score.missing == 2);
  CHECK(score.add_auc == doctest::Approx(50.0));  // half the frames perfect, half failed
  CHECK(score.deg5cm5 == doctest::Approx(50.0));
  CHECK(score.iou25 == doctest::Approx(50.0));
  CHECK(score.rotation_error_deg == 0.0);  // mean over the frames that have a pose
  // No pose at all: every rate 0, the mean errors not a number (printed n/a, JSON null), not 0.
  const bt::SequenceScore none = bt::scoreSequence(model, truth, std::vector<std::optional<bt::SE3d>>(4));
  CHECK(none.missing == 4);
  CHECK(none.adds_auc == 0.0);
  CHECK(std::isnan(none.rotation_error_deg));
  CHECK(std::isnan(none.translation_error_cm));
  const std::string table = bt::formatScoreTable({{"none", none}});
  CHECK(table.find("n/a") != std::string::npos);
  CHECK(table.find("0.00dg") == std::string::npos);
}

TEST_CASE("error plot: ticks at 1, 2 or 5 times a power of ten, one panel per series") {
  const auto check = [](double peak, double step, double end) {
    const bundletrack::viz::Ticks t = bundletrack::viz::niceTicks(peak);
    CAPTURE(peak);
    CHECK(t.step == doctest::Approx(step));
    CHECK(t.end == doctest::Approx(end));
  };
  check(0.44, 0.1, 0.5);
  check(24.86, 5.0, 25.0);
  check(201.26, 50.0, 250.0);
  check(1.0, 0.2, 1.0);
  check(7.0, 2.0, 8.0);
  check(0.0, 1.0, 1.0);  // nothing to show: a unit axis
  CHECK(bundletrack::viz::niceTicks(99.0, 10).step == doctest::Approx(10.0));
  const std::vector<double> errors = {0.1, 0.2, std::nan(""), 0.4};
  const cv::Mat plot = bundletrack::viz::plotErrors({{"a [deg]", errors}, {"b [cm]", errors}}, {false, false, true, false});
  CHECK(plot.cols == 900);
  CHECK(plot.rows == 34 + 2 * 220 + 40 + 46);
  CHECK(cv::countNonZero(plot.reshape(1) != 255) > 0);
}
