// A new residual term, written outside the library (feature_point_to_plane.hpp), is one header and
// one Term in an energy: its Jacobian against finite differences, and a tracker that uses it.
#include <doctest/doctest.h>

#include <random>

#include "bundletrack/default_tracker.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "cost_gradient.hpp"
#include "feature_point_to_plane.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

static_assert(bt::Residual<bt::testing::FeaturePointToPlane>);

TEST_CASE("a test-only feature point-to-plane term: its normal equations are the finite-difference gradient") {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const bt::SE3d T_i(bt::SO3d::exp(Eigen::Vector3d(0.3, -0.2, 0.1)), Eigen::Vector3d(0.02, -0.01, 0.7));
  const bt::SE3d T_j(bt::SO3d::exp(Eigen::Vector3d(0.25, -0.1, 0.3)), Eigen::Vector3d(0.05, 0.01, 0.65));
  bt::Keyframe ki, kj;
  std::vector<bt::FeatureMatch> matches;
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector3d p_obj(0.05 * normal(rng), 0.05 * normal(rng), 0.05 * normal(rng));
    const Eigen::Vector3d n_obj = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    ki.features.points.push_back((T_i * p_obj).cast<float>());
    ki.features.normals.push_back((T_i.rotation() * n_obj).cast<float>());
    kj.features.points.push_back((T_j * p_obj).cast<float>());
    kj.features.normals.push_back((T_j.rotation() * n_obj).cast<float>());
    matches.push_back({k, k});
  }
  using Plugin = bt::testing::FeaturePointToPlane;
  const auto system = [&](const bt::SE3d& A, const bt::SE3d& B) {
    bt::PairSystem s;
    Plugin{}.linearise(Plugin::input(bt::EdgeView{ki, kj, matches}), A, B, bt::TrivialLoss{}, 1.0, s);
    return s;
  };
  // Off the true poses, so that the residuals are not zero.
  const bt::SE3d A = T_i * bt::SE3d::exp((bt::SE3d::Tangent() << 0.003, -0.002, 0.001, 0.02, 0.01, -0.015).finished());
  const bt::SE3d B = T_j * bt::SE3d::exp((bt::SE3d::Tangent() << -0.001, 0.002, 0.003, -0.01, 0.02, 0.01).finished());
  const bt::PairSystem at = system(A, B);
  REQUIRE(at.residuals == 40);
  const Eigen::Matrix<double, 12, 1> gradient =
      halfCostGradient([&](const bt::SE3d& T_a, const bt::SE3d& T_b) { return system(T_a, T_b).cost; }, A, B, 1e-7);
  CAPTURE(gradient.transpose());
  CAPTURE(at.b.transpose());
  CHECK((gradient - at.b).norm() <= 1e-6 * at.b.norm());
}

TEST_CASE("a tracker with the test-only term in its energy tracks the synthetic box") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 30;
  settings.speed = 2.0;
  const auto camera = settings.camera.cast<float>();
  const synth::SyntheticScene scene(settings);
  using WithPlugin = bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>,
                                bt::Term<bt::testing::FeaturePointToPlane, bt::HuberLoss>,
                                bt::Term<bt::DensePointToPlane, bt::HuberLoss>>;
  bt::Tracker<WithPlugin, bt::PCG, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, bt::SurfaceAgreement> tracker(camera);
  bt::DefaultTracker without(camera);
  std::vector<bt::SE3d> truth, estimate;
  int lost = 0;
  double largest_difference = 0.0;
  for (int i = 0; i < settings.frames; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
    const bt::TrackResult with_term = i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame);
    const bt::TrackResult plain = i == 0 ? without.initialize(frame, f.T_cam_obj) : without.track(frame);
    lost += with_term.status == bt::TrackStatus::Lost;
    largest_difference = std::max(largest_difference, (with_term.T_cam_obj.matrix() - plain.T_cam_obj.matrix()).cwiseAbs().maxCoeff());
    truth.push_back(f.T_cam_obj);
    estimate.push_back(with_term.T_cam_obj);
  }
  const bt::SequenceScore score = bt::scoreSequence(scene.objectMesh().sampleSurface(1000, 1), truth, estimate);
  MESSAGE("with the point-to-plane feature term: ADD-S " << score.adds_auc << ", largest pose difference to the default "
                                                         << largest_difference);
  CHECK(lost == 0);
  CHECK(score.adds_auc >= 95.0);
  CHECK(largest_difference > 1e-6);  // the term takes part in the optimisation
}
