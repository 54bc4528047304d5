// Kabsch, RANSAC and matching against exact ground truth.
#include <doctest/doctest.h>

#include <numeric>
#include <random>

#include "bundletrack/eval/pose_metrics.hpp"
#include "bundletrack/features/matching.hpp"
#include "bundletrack/registration/ransac.hpp"

namespace bt = bundletrack;

namespace {

bt::SE3d randomPose(std::mt19937& rng, double max_angle) {
  std::normal_distribution<double> normal;
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  std::uniform_real_distribution<double> angle(0.2 * max_angle, max_angle);
  return bt::SE3d(bt::SO3d::exp(angle(rng) * axis), Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 0.1);
}

// Points on a 10 cm object with unit normals, and their images under T (exact), as FrameFeatures.
void makeCorrespondingFeatures(std::mt19937& rng, const bt::SE3d& T, int count, bt::FrameFeatures& first,
                               bt::FrameFeatures& second) {
  std::uniform_real_distribution<float> coord(-0.05f, 0.05f);
  std::normal_distribution<float> normal;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3f p(coord(rng), coord(rng), 0.7f + coord(rng));
    const Eigen::Vector3f n = Eigen::Vector3f(normal(rng), normal(rng), -3.0f).normalized();
    first.points.push_back(p);
    first.normals.push_back(n);
    second.points.push_back(T.cast<float>() * p);
    second.normals.push_back(T.rotation().cast<float>() * n);
  }
}

std::vector<bt::FeatureMatch> identityMatches(int count) {
  std::vector<bt::FeatureMatch> matches;
  for (int i = 0; i < count; ++i) matches.push_back({i, i});
  return matches;
}

}  // namespace

TEST_CASE("kabsch recovers a random rigid transform exactly from noise-free points") {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const bt::SE3d T = randomPose(rng, 3.1);
    std::vector<Eigen::Vector3d> a, b;
    std::normal_distribution<double> normal;
    for (int i = 0; i < 10; ++i) {
      a.emplace_back(normal(rng), normal(rng), normal(rng));
      b.push_back(T * a.back());
    }
    const bt::SE3d estimate = bt::kabsch(a, b);
    CHECK((estimate.matrix() - T.matrix()).cwiseAbs().maxCoeff() < 1e-10);
  }
}

TEST_CASE("kabsch returns a rotation, not a reflection, for planar and mirrored input") {
  // Coplanar points (z = 0) mapped by a rotation: the cross-covariance has rank 2 and a naive
  // V U^T can have determinant -1.
  std::vector<Eigen::Vector3d> a = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.3, 0.7, 0}};
  const bt::SE3d T(bt::SO3d::exp(Eigen::Vector3d(0.3, -0.2, 2.5)), Eigen::Vector3d(0.1, 0.2, 0.3));
  std::vector<Eigen::Vector3d> b;
  for (const auto& p : a) b.push_back(T * p);
  const bt::SE3d estimate = bt::kabsch(a, b);
  CHECK(estimate.rotationMatrix().determinant() == doctest::Approx(1.0));
  CHECK((estimate.matrix() - T.matrix()).cwiseAbs().maxCoeff() < 1e-10);
  // A mirror image cannot be matched by a rotation: the result must still be a proper rotation.
  std::vector<Eigen::Vector3d> mirrored;
  for (const auto& p : a) mirrored.emplace_back(p.x(), p.y(), -p.z() + 0.1 * p.x() * p.y());
  CHECK(bt::kabsch(a, mirrored).rotationMatrix().determinant() == doctest::Approx(1.0));
}

TEST_CASE("RANSAC recovers the transform within 1 mm and 0.1 degree with 60% outliers") {
  std::mt19937 rng(2);
  const bt::SE3d T = randomPose(rng, 0.5);
  bt::FrameFeatures first, second;
  makeCorrespondingFeatures(rng, T, 200, first, second);
  // 0.5 mm of noise on the inliers' targets, then 60% of the matches point at random targets.
  std::normal_distribution<float> noise(0.0f, 0.0005f);
  for (auto& p : second.points) p += Eigen::Vector3f(noise(rng), noise(rng), noise(rng));
  std::vector<bt::FeatureMatch> matches = identityMatches(200);
  std::uniform_int_distribution<int> any(0, 199);
  for (int i = 0; i < 120; ++i) matches[i].second = (i + 1 + any(rng) % 198) % 200;  // never itself
  const bt::RansacResult result = bt::Ransac().estimate(first, second, matches);
  REQUIRE(result.found());
  CHECK(bt::translationError(T, result.T_second_first) < 1e-3);
  CHECK(bt::rotationErrorDeg(T, result.T_second_first) < 0.1);
  CHECK(result.inliers.size() >= 78);  // the 80 true matches, less any noise beyond 5 mm (none at 0.5 mm)
  CHECK(result.inliers.size() <= 82);  // random outliers landing within 5 mm by chance are rare
  CHECK(result.inlierRatio() == doctest::Approx(double(result.inliers.size()) / 200.0));
  CHECK(result.trials < 2000);  // adaptive: w = 0.4 needs ~105 trials at 99.9%
}

TEST_CASE("RANSAC is deterministic and independent of parallel scoring") {
  std::mt19937 rng(3);
  const bt::SE3d T = randomPose(rng, 0.5);
  bt::FrameFeatures first, second;
  makeCorrespondingFeatures(rng, T, 100, first, second);
  auto matches = identityMatches(100);
  for (int i = 0; i < 50; ++i) matches[i].second = (i + 7) % 100;
  bt::RansacSettings serial;
  serial.execution = bt::Execution::Serial;
  const auto a = bt::Ransac().estimate(first, second, matches), b = bt::Ransac(serial).estimate(first, second, matches);
  CHECK(a.inliers == b.inliers);
  CHECK(a.trials == b.trials);
  CHECK((a.T_second_first.matrix() - b.T_second_first.matrix()).norm() == 0.0);
}

TEST_CASE("the normal check rejects a hypothesis that the distance check alone accepts") {
  // Two point sets related by T, but the second frame's normals are flipped sideways on half of
  // the points (as when a match lands on the other side of a thin part): those matches satisfy the
  // 5 mm distance test under T but not the 45 degree normal test.
  std::mt19937 rng(4);
  const bt::SE3d T = randomPose(rng, 0.3);
  bt::FrameFeatures first, second;
  makeCorrespondingFeatures(rng, T, 40, first, second);
  for (int i = 0; i < 20; ++i) second.normals[i] = second.normals[i].unitOrthogonal();  // 90 degrees off
  const auto matches = identityMatches(40);
  bt::RansacSettings distance_only;
  distance_only.inlier_normal_angle_deg = 180.0f;
  const auto with_normals = bt::Ransac().estimate(first, second, matches);
  const auto without_normals = bt::Ransac(distance_only).estimate(first, second, matches);
  CHECK(without_normals.inliers.size() == 40);
  CHECK(with_normals.inliers.size() == 20);
  for (const int i : with_normals.inliers) CHECK(i >= 20);
}

TEST_CASE("RANSAC rejects degenerate input instead of returning a pose") {
  bt::FrameFeatures first, second;
  for (int i = 0; i < 30; ++i) {  // collinear points: rotation about the line is unobservable
    first.points.emplace_back(0.01f * float(i), 0.0f, 0.7f);
    first.normals.emplace_back(0.0f, 0.0f, -1.0f);
  }
  second = first;
  const auto result = bt::Ransac().estimate(first, second, identityMatches(30));
  CHECK_FALSE(result.found());
  CHECK(bt::Ransac().estimate(first, second, identityMatches(2)).trials == 0);
}

TEST_CASE("mutual matching with the ratio test is symmetric and gated by a known pose") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  bt::FrameFeatures a, b;
  a.descriptors.create(60, 16, CV_32F);
  b.descriptors.create(50, 16, CV_32F);
  for (int r = 0; r < a.descriptors.rows; ++r)
    for (int c = 0; c < 16; ++c) a.descriptors.at<float>(r, c) = uniform(rng);
  // b's first 40 descriptors are noisy copies of a's rows 10..49, the rest random.
  for (int r = 0; r < b.descriptors.rows; ++r)
    for (int c = 0; c < 16; ++c)
      b.descriptors.at<float>(r, c) = r < 40 ? a.descriptors.at<float>(r + 10, c) + 0.02f * uniform(rng) : uniform(rng);
  for (int i = 0; i < 60; ++i) a.points.emplace_back(0.01f * float(i), 0.0f, 0.7f), a.normals.emplace_back(0, 0, -1);
  for (int i = 0; i < 50; ++i) b.points.emplace_back(0.01f * float(i + 10), 0.0f, 0.7f), b.normals.emplace_back(0, 0, -1);
  const bt::MatchSettings settings;
  const auto forward = bt::matchFeatures(a, b, settings), backward = bt::matchFeatures(b, a, settings);
  REQUIRE(forward.size() == backward.size());
  for (std::size_t k = 0; k < forward.size(); ++k) {
    const bool mirrored = std::find(backward.begin(), backward.end(), bt::FeatureMatch{forward[k].second, forward[k].first}) !=
                          backward.end();
    CHECK(mirrored);
  }
  int correct = 0;
  for (const auto& m : forward) correct += m.first == m.second + 10;
  CHECK(correct >= 38);  // nearly all 40 planted pairs survive ratio and mutual tests
  CHECK(int(forward.size()) - correct <= 2);
  // A gate with the true relative pose (identity here) keeps the correct matches; one that is off
  // by 5 cm removes them all.
  bt::MatchSettings exhaustive = settings;
  exhaustive.guided = false;
  const bt::MatchGate truth{bt::SE3f(), 0.02f, 45.0f};
  const auto gated = bt::matchFeatures(a, b, exhaustive, truth);
  CHECK(gated.size() == std::size_t(correct));
  const bt::SE3f shifted(bt::SO3f(), Eigen::Vector3f(0.05f, 0.0f, 0.0f));
  CHECK(bt::matchFeatures(a, b, exhaustive, bt::MatchGate{shifted, 0.02f, 45.0f}).empty());
  // Guided matching finds every gated exhaustive match (the nearest neighbour overall is the
  // nearest among the gated candidates, and the runner-up among them is no closer); with the
  // true pose it finds all 40 planted pairs, and the only others pair a keypoint without a true
  // partner (a's rows 0..9 and 50..59) with a random neighbour of b within the 2 cm gate.
  const auto guided = bt::matchFeatures(a, b, settings, truth);
  for (const auto& m : gated) CHECK(std::find(guided.begin(), guided.end(), m) != guided.end());
  int planted = 0, other = 0;
  for (const auto& m : guided) {
    if (m.first == m.second + 10 && m.second < 40) ++planted;
    else other += m.first < 10 || m.first >= 50 ? 0 : 1;
    CHECK(std::abs(m.first - (m.second + 10)) <= 2);
  }
  CHECK(planted == 40);
  CHECK(other == 0);
  // Under a pose 5 cm off no planted pair is a candidate (what remains is for RANSAC to reject).
  for (const auto& m : bt::matchFeatures(a, b, settings, bt::MatchGate{shifted, 0.02f, 45.0f}))
    CHECK(m.first != m.second + 10);
}

TEST_CASE("exhaustive matching and descriptor distances equal OpenCV's brute-force matcher (L2 and Hamming)") {
  // The reference: cv::BFMatcher's two nearest neighbours in each direction, then the mutual ratio
  // test. Descriptors in clusters (SIFT-like floats, ORB-like bytes) so that the ratio test both
  // passes and fails; equality is exact because both sides use OpenCV's distance kernels.
  std::mt19937 rng(11);
  const auto reference = [](const bt::FrameFeatures& a, const bt::FrameFeatures& b, float ratio) {
    const cv::BFMatcher matcher(a.norm_type);
    const auto nearest = [&](const cv::Mat& query, const cv::Mat& train) {
      std::vector<std::vector<cv::DMatch>> knn;
      matcher.knnMatch(query, train, knn, 2);
      std::vector<bt::TwoNearest> two(knn.size());
      for (std::size_t k = 0; k < knn.size(); ++k) two[k] = {knn[k][0].trainIdx, knn[k][0].distance, knn[k][1].distance};
      return std::pair{two, knn};
    };
    const auto [forward, knn] = nearest(a.descriptors, b.descriptors);
    for (int i = 0; i < a.descriptors.rows; ++i)
      CHECK(bt::descriptorDistance(a.descriptors, i, b.descriptors, knn[std::size_t(i)][0].trainIdx, a.norm_type) ==
            knn[std::size_t(i)][0].distance);
    return bt::mutualMatches(forward, nearest(b.descriptors, a.descriptors).first, a, b, ratio, std::nullopt);
  };
  // a: random rows, its rows 200..229 copies of rows 0..29 (L2: 1e-3 apart), so b's copies of
  // those are ambiguous and fail the ratio test; b: rows 0..149 noisy copies of a's rows, the rest
  // random.
  const auto features = [&](int rows, int cols, int type, int norm, const cv::Mat* copy_of, int copies, int shift) {
    bt::FrameFeatures f;
    f.norm_type = norm;
    f.descriptors.create(rows, cols, type);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::uniform_int_distribution<int> byte(0, 255), bit(0, 7);
    for (int r = 0; r < rows; ++r) {
      f.points.emplace_back(0.0f, 0.0f, 0.7f), f.normals.emplace_back(0.0f, 0.0f, -1.0f);
      const bool twin = r >= shift && r < shift + 30;
      const cv::Mat* source = r < copies ? copy_of : twin ? &f.descriptors : nullptr;
      const int from = r < copies ? r : r - shift;
      const float noise = twin ? 1e-3f : 0.05f;
      for (int c = 0; c < cols; ++c) {
        if (type == CV_32F)
          f.descriptors.at<float>(r, c) = source ? source->at<float>(from, c) + noise * (unit(rng) - 0.5f) : unit(rng);
        else
          f.descriptors.at<uchar>(r, c) =
              source ? uchar(source->at<uchar>(from, c) ^ (!twin && c % 8 == 0 ? 1 << bit(rng) : 0)) : uchar(byte(rng));
      }
    }
    return f;
  };
  const bt::MatchSettings settings;
  for (const auto& [type, cols, norm] : {std::tuple{CV_32F, 128, int(cv::NORM_L2)}, std::tuple{CV_8U, 32, int(cv::NORM_HAMMING)}}) {
    const bt::FrameFeatures a = features(300, cols, type, norm, nullptr, 0, 200);
    const bt::FrameFeatures b = features(250, cols, type, norm, &a.descriptors, 150, 250);
    const auto expected = reference(a, b, settings.ratio);
    CHECK(expected.size() >= 100);  // most of the 120 unambiguous copies
    CHECK(expected.size() <= 125);  // not the 30 ambiguous ones
    CHECK(bt::matchFeatures(a, b, settings) == expected);
  }
}

TEST_CASE("the two nearest candidates do not depend on the order they are offered in, ties included") {
  // Distances with ties (multiples of 0.5 among 12 candidates): in index order the lower index
  // wins a tie, as cv::BFMatcher; every shuffled order must give the same nearest, its distance and
  // the second distance.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> halves(1, 6);
  for (int round = 0; round < 200; ++round) {
    std::vector<float> distance(12);
    for (float& d : distance) d = 0.5f * float(halves(rng));
    bt::TwoNearest in_order;
    for (int j = 0; j < 12; ++j) in_order.offer(distance[std::size_t(j)], j);
    std::vector<int> order(12);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    bt::TwoNearest shuffled;
    for (const int j : order) shuffled.offer(distance[std::size_t(j)], j);
    const auto lowest = std::min_element(distance.begin(), distance.end());
    REQUIRE(in_order.index == int(lowest - distance.begin()));  // the first of the smallest
    CHECK(shuffled.index == in_order.index);
    CHECK(shuffled.best == in_order.best);
    CHECK(shuffled.second == in_order.second);
  }
}

TEST_CASE("guided matching equals the exhaustive loop over the pairs the gate admits") {
  // Keypoints 1 cm apart on average, descriptors clustered so that several candidates per gate
  // compete, a gate of 2 cm and 45 degrees under a known pose: the reference offers every pair.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal;
  const bt::SE3d T = randomPose(rng, 0.3);
  bt::FrameFeatures a, b;
  makeCorrespondingFeatures(rng, T, 400, a, b);
  for (auto& p : b.points) p += 0.004f * Eigen::Vector3f(normal(rng), normal(rng), normal(rng));
  a.descriptors.create(400, 8, CV_32F);
  b.descriptors.create(400, 8, CV_32F);
  for (int r = 0; r < 400; ++r)
    for (int c = 0; c < 8; ++c) {
      a.descriptors.at<float>(r, c) = float(r % 5) + unit(rng);
      b.descriptors.at<float>(r, c) = float(r % 5) + unit(rng);
    }
  const bt::MatchGate gate{T.cast<float>(), 0.02f, 45.0f};
  std::vector<bt::TwoNearest> forward(400), backward(400);
  const auto bounds = gate.surface.bounds<float>();
  for (int i = 0; i < 400; ++i)
    for (int j = 0; j < 400; ++j) {
      const Eigen::Vector3f moved = gate.T_second_first * a.points[std::size_t(i)];
      const Eigen::Vector3f normal_moved = gate.T_second_first.rotation() * a.normals[std::size_t(i)];
      if (!bounds.admits((moved - b.points[std::size_t(j)]).squaredNorm(), normal_moved.dot(b.normals[std::size_t(j)])))
        continue;
      const float d = bt::descriptorDistance(a.descriptors, i, b.descriptors, j, cv::NORM_L2);
      forward[std::size_t(i)].offer(d, j);
      backward[std::size_t(j)].offer(d, i);
    }
  const bt::MatchSettings settings;
  const auto expected = bt::mutualMatches(forward, backward, a, b, settings.ratio, std::nullopt);
  const auto guided = bt::matchFeatures(a, b, settings, gate);
  CHECK(expected.size() > 20);
  CHECK(guided == expected);
}
