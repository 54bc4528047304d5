// SO(3) and SE(3): group laws, exp/log round trips near 0 and pi, and every Jacobian against
// central finite differences computed with the same scalar type.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "bundletrack/core/se3.hpp"

namespace bt = bundletrack;

namespace {

template <typename Scalar>
struct Tolerance;
template <>
struct Tolerance<float> {
  static constexpr float exact = 2e-5f;  // ~100 ulp for composite expressions of O(1) values
  static constexpr float fd_step = 2e-3f;  // ~cbrt(eps) for central differences
  static constexpr float fd = 2e-3f;  // step^2 truncation + eps/step rounding, with margin
};
template <>
struct Tolerance<double> {
  static constexpr double exact = 1e-11;
  static constexpr double fd_step = 1e-5;
  static constexpr double fd = 1e-7;
};

template <typename Scalar>
Eigen::Matrix<Scalar, 3, 1> randomVector(std::mt19937& rng, Scalar length) {
  std::normal_distribution<double> normal;
  Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  return (v.normalized() * double(length)).cast<Scalar>();
}

// Rotation angles that exercise every branch: zero, the Taylor region, generic, close to pi.
template <typename Scalar>
std::vector<Scalar> testAngles() {
  const Scalar pi = std::numbers::pi_v<Scalar>;
  return {Scalar(0), Scalar(1e-6), Scalar(0.5) * bt::kSmallAngle<Scalar>, Scalar(2) * bt::kSmallAngle<Scalar>,
          Scalar(0.7), Scalar(2.0), pi - Scalar(1e-2), pi - Scalar(1e-4)};
}

template <typename Scalar>
std::vector<bt::SE3<Scalar>> testPoses(std::mt19937& rng) {
  std::vector<bt::SE3<Scalar>> poses;
  for (const Scalar angle : testAngles<Scalar>()) {
    const auto w = randomVector<Scalar>(rng, angle);
    poses.emplace_back(bt::SO3<Scalar>::exp(w), randomVector<Scalar>(rng, Scalar(0.8)));
  }
  return poses;
}

template <typename Derived, typename Other>
double maxAbsDiff(const Eigen::MatrixBase<Derived>& a, const Eigen::MatrixBase<Other>& b) {
  return (a.template cast<double>() - b.template cast<double>()).cwiseAbs().maxCoeff();
}

// Central differences of f(x) with respect to the N-vector x, column by column.
template <int Rows, int N, typename Scalar, typename F>
Eigen::Matrix<Scalar, Rows, N> centralDifferences(F&& f, Scalar step) {
  Eigen::Matrix<Scalar, Rows, N> J;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<Scalar, N, 1> d = Eigen::Matrix<Scalar, N, 1>::Zero();
    d[i] = step;
    J.col(i) = (f(d) - f(-d)) / (Scalar(2) * step);
  }
  return J;
}

}  // namespace

TEST_CASE_TEMPLATE("SO3 hat and vee are inverse and hat is the cross product", Scalar, float, double) {
  std::mt19937 rng(1);
  const auto w = randomVector<Scalar>(rng, Scalar(1.3));
  const auto p = randomVector<Scalar>(rng, Scalar(0.4));
  CHECK(maxAbsDiff(bt::SO3<Scalar>::vee(bt::SO3<Scalar>::hat(w)), w) == 0.0);
  CHECK(maxAbsDiff(bt::SO3<Scalar>::hat(w) * p, w.cross(p)) < Tolerance<Scalar>::exact);
}

TEST_CASE_TEMPLATE("SO3 exp matches Eigen's AngleAxis and log inverts it", Scalar, float, double) {
  std::mt19937 rng(2);
  for (const Scalar angle : testAngles<Scalar>()) {
    CAPTURE(angle);
    const auto w = randomVector<Scalar>(rng, angle);
    const auto R = bt::SO3<Scalar>::exp(w);
    const Eigen::Matrix<Scalar, 3, 3> reference =
        angle == Scalar(0) ? Eigen::Matrix<Scalar, 3, 3>::Identity()
                           : Eigen::AngleAxis<Scalar>(angle, w.normalized()).toRotationMatrix();
    CHECK(maxAbsDiff(R.matrix(), reference) < Tolerance<Scalar>::exact);
    CHECK(std::abs(double(R.angle()) - double(angle)) < 10 * Tolerance<Scalar>::exact);
    // At pi the rotation vector is ambiguous up to sign, so compare rotations, not vectors.
    CHECK(maxAbsDiff(bt::SO3<Scalar>::exp(R.log()).matrix(), R.matrix()) < Tolerance<Scalar>::exact);
    if (angle < Scalar(3)) CHECK(maxAbsDiff(R.log(), w) < 10 * Tolerance<Scalar>::exact);
  }
}

TEST_CASE_TEMPLATE("SE3 group laws: composition, inverse, action and matrix agree", Scalar, float, double) {
  std::mt19937 rng(3);
  const auto poses = testPoses<Scalar>(rng);
  const auto p = randomVector<Scalar>(rng, Scalar(0.3));
  for (size_t i = 0; i + 1 < poses.size(); ++i) {
    const auto& a = poses[i];
    const auto& b = poses[i + 1];
    CHECK(maxAbsDiff((a * b).matrix(), a.matrix() * b.matrix()) < Tolerance<Scalar>::exact);
    CHECK(maxAbsDiff((a * a.inverse()).matrix(), Eigen::Matrix<Scalar, 4, 4>::Identity()) < Tolerance<Scalar>::exact);
    CHECK(maxAbsDiff(a * p, (a.matrix() * p.homogeneous()).template head<3>()) < Tolerance<Scalar>::exact);
    CHECK(maxAbsDiff(bt::SE3<Scalar>::fromMatrix(a.matrix()).matrix(), a.matrix()) < Tolerance<Scalar>::exact);
  }
}

TEST_CASE_TEMPLATE("SE3 exp(log(T)) = T near 0, generic and near pi", Scalar, float, double) {
  std::mt19937 rng(4);
  for (const auto& T : testPoses<Scalar>(rng)) {
    CAPTURE(T.rotation().angle());
    CHECK(maxAbsDiff(bt::SE3<Scalar>::exp(T.log()).matrix(), T.matrix()) < 10 * Tolerance<Scalar>::exact);
    // log(T) through the matrix exponential series of hat(xi) (independent of the closed form).
    const auto xi = T.log();
    const Eigen::Matrix<double, 4, 4> X = bt::SE3<double>::hat(xi.template cast<double>());
    Eigen::Matrix<double, 4, 4> series = Eigen::Matrix<double, 4, 4>::Identity(), term = series;
    for (int k = 1; k < 40; ++k) {
      term = term * X / double(k);
      series += term;
    }
    CHECK(maxAbsDiff(series, T.matrix()) < 10 * Tolerance<Scalar>::exact);
  }
}

TEST_CASE_TEMPLATE("SE3 adjoint: T exp(d) T^-1 = exp(Adj(T) d)", Scalar, float, double) {
  std::mt19937 rng(5);
  Eigen::Matrix<Scalar, 6, 1> d;
  d.template head<3>() = randomVector<Scalar>(rng, Scalar(0.2));
  d.template tail<3>() = randomVector<Scalar>(rng, Scalar(0.3));
  for (const auto& T : testPoses<Scalar>(rng)) {
    const auto lhs = T * bt::SE3<Scalar>::exp(d) * T.inverse();
    const auto rhs = bt::SE3<Scalar>::exp(T.adjoint() * d);
    CHECK(maxAbsDiff(lhs.matrix(), rhs.matrix()) < 10 * Tolerance<Scalar>::exact);
  }
}

TEST_CASE_TEMPLATE("SO3 Jacobians against finite differences", Scalar, float, double) {
  using SO3 = bt::SO3<Scalar>;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  std::mt19937 rng(6);
  const Scalar h = Tolerance<Scalar>::fd_step;
  for (const Scalar angle : testAngles<Scalar>()) {
    if (angle > Scalar(3)) continue;  // log jumps at pi: differences across it are meaningless
    CAPTURE(angle);
    const Vec3 w = randomVector<Scalar>(rng, angle);
    const SO3 R = SO3::exp(w);
    // Right Jacobian: log(exp(w)^-1 exp(w + d)) ~= J_r d.
    const auto right = centralDifferences<3, 3>([&](const Vec3& d) { return (R.inverse() * SO3::exp(w + d)).log(); }, h);
    CHECK(maxAbsDiff(SO3::rightJacobian(w), right) < Tolerance<Scalar>::fd);
    const auto left = centralDifferences<3, 3>([&](const Vec3& d) { return (SO3::exp(w + d) * R.inverse()).log(); }, h);
    CHECK(maxAbsDiff(SO3::leftJacobian(w), left) < Tolerance<Scalar>::fd);
    CHECK(maxAbsDiff(SO3::rightJacobianInverse(w) * SO3::rightJacobian(w), Eigen::Matrix<Scalar, 3, 3>::Identity()) <
          Tolerance<Scalar>::fd);
    CHECK(maxAbsDiff(SO3::leftJacobianInverse(w) * SO3::leftJacobian(w), Eigen::Matrix<Scalar, 3, 3>::Identity()) <
          Tolerance<Scalar>::fd);
  }
}

TEST_CASE_TEMPLATE("SE3 Jacobians against finite differences", Scalar, float, double) {
  using SE3 = bt::SE3<Scalar>;
  using Vec6 = Eigen::Matrix<Scalar, 6, 1>;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  std::mt19937 rng(7);
  const Scalar h = Tolerance<Scalar>::fd_step;
  const Vec3 p = randomVector<Scalar>(rng, Scalar(0.5));
  for (const auto& T : testPoses<Scalar>(rng)) {
    CAPTURE(T.rotation().angle());
    const auto action = centralDifferences<3, 6>([&](const Vec6& d) { return Vec3(T * SE3::exp(d) * p); }, h);
    CHECK(maxAbsDiff(T.J_action_delta(p), action) < Tolerance<Scalar>::fd);
    const auto inverse_action =
        centralDifferences<3, 6>([&](const Vec6& d) { return Vec3((T * SE3::exp(d)).inverse() * p); }, h);
    CHECK(maxAbsDiff(T.J_inverseAction_delta(p), inverse_action) < Tolerance<Scalar>::fd);

    if (T.rotation().angle() > Scalar(3)) continue;  // log jumps at pi
    const Vec6 xi = T.log();
    const auto right = centralDifferences<6, 6>([&](const Vec6& d) { return Vec6((T.inverse() * SE3::exp(xi + d)).log()); }, h);
    CHECK(maxAbsDiff(SE3::rightJacobian(xi), right) < Tolerance<Scalar>::fd);
    const auto left = centralDifferences<6, 6>([&](const Vec6& d) { return Vec6((SE3::exp(xi + d) * T.inverse()).log()); }, h);
    CHECK(maxAbsDiff(SE3::leftJacobian(xi), left) < Tolerance<Scalar>::fd);
    const Eigen::Matrix<Scalar, 6, 6> I = Eigen::Matrix<Scalar, 6, 6>::Identity();
    CHECK(maxAbsDiff(SE3::rightJacobianInverse(xi) * SE3::rightJacobian(xi), I) < Tolerance<Scalar>::fd);
    CHECK(maxAbsDiff(SE3::leftJacobianInverse(xi) * SE3::leftJacobian(xi), I) < Tolerance<Scalar>::fd);
  }
}

TEST_CASE("rotation geodesic equals the arccos of the trace formula") {
  std::mt19937 rng(8);
  const auto a = bt::SO3d::exp(randomVector<double>(rng, 1.1));
  const auto b = bt::SO3d::exp(randomVector<double>(rng, 2.2));
  const double trace = (a.matrix().transpose() * b.matrix()).trace();
  CHECK(bt::rotationGeodesic(a, b) == doctest::Approx(std::acos((trace - 1.0) / 2.0)).epsilon(1e-9));
}
