// geometricStability against surfaces whose free motions are known: a plane slides and spins in
// itself, a sphere turns about its centre, a cylinder twists about and slides along its axis;
// three faces of a box hold every direction. Independent of where the surface sits, and the
// normal averaging removes most of what noisy normals add to a plane. And surface agreement, the
// pose verifier, on a box's corner seen from two sides.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/graph/keyframe.hpp"
#include "bundletrack/graph/pose_graph.hpp"
#include "bundletrack/verification/geometric_stability.hpp"
#include "bundletrack/verification/surface_agreement.hpp"

namespace bt = bundletrack;

namespace {

/// A size x size grid whose cell (x, y) holds surface(u, v) for u, v in [0, 1] (point, normal).
bt::SurfaceGrid gridOf(int size, const std::function<std::pair<Eigen::Vector3d, Eigen::Vector3d>(double, double)>& surface,
                       const bt::SE3d& placed = {}) {
  bt::SurfaceGrid grid;
  grid.points.create(size, size, CV_32FC3);
  grid.normals.create(size, size, CV_32FC3);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      auto [p, n] = surface(x / double(size - 1), y / double(size - 1));
      p = placed * p;
      n = placed.rotation() * n;
      grid.points.at<cv::Vec3f>(y, x) = cv::Vec3f(float(p.x()), float(p.y()), float(p.z()));
      grid.normals.at<cv::Vec3f>(y, x) = cv::Vec3f(float(n.x()), float(n.y()), float(n.z()));
    }
  }
  bt::indexCells(grid);
  return grid;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> plane(double u, double v) {
  return {{0.2 * u - 0.1, 0.2 * v - 0.1, 1.0}, {0.0, 0.0, -1.0}};
}

/// A cap of a sphere of radius 0.1 around the camera's view of it.
std::pair<Eigen::Vector3d, Eigen::Vector3d> sphere(double u, double v) {
  const double theta = 2.0 * (u - 0.5), phi = 2.0 * (v - 0.5);  // up to +-57 degrees
  const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(phi), -std::cos(theta) * std::cos(phi));
  return {Eigen::Vector3d(0, 0, 1) + 0.1 * n, n};
}

/// The front half of a cylinder of radius 0.05 along y.
std::pair<Eigen::Vector3d, Eigen::Vector3d> cylinder(double u, double v) {
  const double theta = 3.0 * (u - 0.5);
  const Eigen::Vector3d n(std::sin(theta), 0.0, -std::cos(theta));
  return {Eigen::Vector3d(0, 0.2 * v - 0.1, 1.0) + 0.05 * n, n};
}

/// Three faces of a box of side 0.2, 0.8 m in front of the camera, meeting at the corner nearest
/// to it (a third of the grid each).
std::pair<Eigen::Vector3d, Eigen::Vector3d> boxCorner(double u, double v) {
  const Eigen::Vector3d corner(-0.1, -0.1, 0.8);
  const double a = 0.2 * (3.0 * u - std::floor(3.0 * std::min(u, 0.999))), b = 0.2 * v;
  if (u < 1.0 / 3.0) return {corner + Eigen::Vector3d(a, b, 0.0), {0, 0, -1}};
  if (u < 2.0 / 3.0) return {corner + Eigen::Vector3d(0.0, b, a), {-1, 0, 0}};
  return {corner + Eigen::Vector3d(a, 0.0, b), {0, -1, 0}};
}

}  // namespace

TEST_CASE("geometric stability: 0 where a motion is free (plane, sphere, cylinder), large for a box corner") {
  for (const int radius : {0, 2}) {
    CAPTURE(radius);
    CHECK(bt::geometricStability(gridOf(40, plane), radius) < 1e-9);
    const double corner = bt::geometricStability(gridOf(60, boxCorner), radius);
    MESSAGE("box corner: " << corner);
    CHECK(corner > 0.1);
  }
  // Exact normals: a sphere turns freely about its centre, a cylinder about its axis. Averaged
  // ones near the rim lean inwards (a truncated neighbourhood), which holds the turn a little.
  for (const auto& curved : {sphere, cylinder}) {
    CHECK(bt::geometricStability(gridOf(40, curved), 0) < 1e-9);
    CHECK(bt::geometricStability(gridOf(40, curved), 2) < 1e-3);
  }
  CHECK(bt::geometricStability(bt::SurfaceGrid{}) == 0.0);
}

TEST_CASE("geometric stability does not depend on where the surface is or how it is turned") {
  const bt::SE3d placed(bt::SO3d::exp(Eigen::Vector3d(0.3, -0.7, 0.2)), Eigen::Vector3d(0.5, -0.2, 1.5));
  const double here = bt::geometricStability(gridOf(60, boxCorner));
  CHECK(bt::geometricStability(gridOf(60, boxCorner, placed)) == doctest::Approx(here).epsilon(1e-5));
}

TEST_CASE("noisy normals make a plane look stable, and averaging 5x5 cells removes most of it") {
  std::mt19937 random(3);
  std::normal_distribution<double> tilt(0.0, 0.12);  // per axis: normals about 10 degrees off
  const auto noisy = [&](double u, double v) {
    auto [p, n] = plane(u, v);
    return std::pair(p, Eigen::Vector3d(tilt(random), tilt(random), -1.0).normalized());
  };
  const bt::SurfaceGrid grid = gridOf(60, noisy);
  const double raw = bt::geometricStability(grid, 0), averaged = bt::geometricStability(grid, 2);
  MESSAGE("noisy plane: " << raw << " raw, " << averaged << " averaged");
  // In-plane translation gathers sum (n.t)^2 ~ N sigma^2 against N along the normal.
  CHECK(raw > 0.5 * 0.12 * 0.12);
  CHECK(averaged < raw / 10.0);
  // Three times noisier readings: the default window is three times as wide.
  bt::SurfaceGrid noisier = grid;
  noisier.noise_scale = 3.0;
  CHECK(bt::geometricStability(noisier) == bt::geometricStability(grid, 6));
  CHECK(bt::geometricStability(grid) == averaged);
}

TEST_CASE("pose stability: the pose graph's information about the object's origin, re-centred and scaled, is the surface's geometric stability") {
  // A pose graph's node information in its own coordinates: point-to-plane rows [m, a x m] of the
  // right perturbation T_cam_obj exp(d), a and m the points and normals in the object frame,
  // whose origin lies far from the points. Re-centred on their centroid and scaled by their RMS
  // radius, its evenness must be what geometricStability computes from the camera-frame surface
  // about its centroid (exact normals: no averaging).
  const bt::SE3d T_cam_obj(bt::SO3d::exp(Eigen::Vector3d(0.4, 0.9, -0.3)), Eigen::Vector3d(0.2, -0.4, 0.3));
  for (const auto& shape : {boxCorner, cylinder, sphere}) {
    const bt::SurfaceGrid grid = gridOf(40, shape);
    Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
    for (const cv::Point& cell : grid.cells) {
      const cv::Vec3f& p = grid.point(cell);
      const cv::Vec3f& n = grid.normal(cell);
      const Eigen::Vector3d a = T_cam_obj.inverse() * Eigen::Vector3d(p[0], p[1], p[2]);
      const Eigen::Vector3d m = T_cam_obj.rotation().inverse() * Eigen::Vector3d(n[0], n[1], n[2]);
      Eigen::Matrix<double, 6, 1> row;
      row << m, a.cross(m);
      information += row * row.transpose();
    }
    const bt::SurfaceSpread spread = bt::spreadOf(grid);
    const double expected = bt::geometricStability(grid, 0);
    const double reported = bt::poseStability(information, T_cam_obj.inverse() * spread.centroid, spread.rms_radius);
    CHECK(reported == doctest::Approx(expected).epsilon(1e-6));
    // Without re-centring the box corner's turns about the far origin read as shifts.
    if (expected > 0.1) CHECK(bt::evenness(information) < 0.5 * expected);
  }
  CHECK(bt::poseStability(Eigen::Matrix<double, 6, 6>::Zero(), Eigen::Vector3d::Zero(), 0.1) == 0.0);
}

namespace {

/// What a camera at `T_world_cam` sees of a box's corner on a 100 x 100 grid (f = 100 px): its
/// front face (z = 1, normal -z) and its right side face (x = 0.1, normal +x, 1 <= z <= 1.2),
/// both 0.2 m tall; camera-frame points and normals, the nearest face where a ray meets both.
bt::SurfaceGrid viewOfBoxCorner(const bt::SE3d& T_world_cam, double noise_scale) {
  bt::SurfaceGrid grid;
  grid.camera = {100.0f, 100.0f, 49.5f, 49.5f};
  grid.noise_scale = noise_scale;
  grid.points = cv::Mat::zeros(100, 100, CV_32FC3);
  grid.normals = cv::Mat::zeros(100, 100, CV_32FC3);
  const bt::SE3d T_cam_world = T_world_cam.inverse();
  const Eigen::Vector3d origin = T_world_cam.translation();
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 100; ++x) {
      const Eigen::Vector3d ray = T_world_cam.rotation() * Eigen::Vector3d((x - 49.5) / 100.0, (y - 49.5) / 100.0, 1.0);
      double nearest = std::numeric_limits<double>::infinity();
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      const auto hit = [&](int axis, double plane, const Eigen::Vector3d& n, auto&& on_face) {
        const double t = (plane - origin[axis]) / ray[axis];
        const Eigen::Vector3d p = origin + t * ray;
        if (t > 0.0 && t < nearest && on_face(p) && n.dot(ray) < 0.0) nearest = t, normal = n;
      };
      hit(2, 1.0, {0, 0, -1}, [](const Eigen::Vector3d& p) { return std::abs(p.x()) <= 0.1 && std::abs(p.y()) <= 0.1; });
      hit(0, 0.1, {1, 0, 0}, [](const Eigen::Vector3d& p) { return p.z() >= 1.0 && p.z() <= 1.2 && std::abs(p.y()) <= 0.1; });
      if (!std::isfinite(nearest)) continue;
      const Eigen::Vector3d p = T_cam_world * (origin + nearest * ray), n = T_cam_world.rotation() * normal;
      grid.points.at<cv::Vec3f>(y, x) = cv::Vec3f(float(p.x()), float(p.y()), float(p.z()));
      grid.normals.at<cv::Vec3f>(y, x) = cv::Vec3f(float(n.x()), float(n.y()), float(n.z()));
    }
  }
  bt::indexCells(grid);
  return grid;
}

}  // namespace

TEST_CASE("surface agreement compares a point only with the views that could have seen it") {
  // A keyframe straight in front of a box's corner sees its front face only; the current view, 45
  // degrees to the right, sees the side face too. Under the true poses the side face's points
  // fall onto the keyframe's front face within the gate where it is widened for far, noisy
  // readings (x5: 5 cm), at right angles to it, behind it: a face the keyframe's camera could not
  // have seen, so it is not compared, and the right pose agrees fully. A pose turned by 180 degrees shows
  // the keyframe the backs of the faces: nothing is compared, and it is refused.
  const bt::SE3d keyframe_camera;  // the world frame: the object's
  const bt::SE3d current_camera(bt::SO3d::exp(Eigen::Vector3d(0, -M_PI / 4, 0)), Eigen::Vector3d(0.75, 0.0, 0.25));
  bt::Keyframe keyframe, current;
  keyframe.surface = viewOfBoxCorner(keyframe_camera, 5.0);
  current.surface = viewOfBoxCorner(current_camera, 5.0);
  int side_face = 0;
  for (const cv::Point& cell : current.surface.cells) side_face += current.surface.normal(cell)[0] < -0.5f;  // +x seen turned
  REQUIRE(side_face > 0);
  REQUIRE(4 * (int(current.surface.cells.size()) - side_face) >= int(current.surface.cells.size()));  // the front face lands: compared
  bt::PoseGraph graph;
  graph.nodes = {&keyframe, &current};
  graph.poses = {keyframe_camera.inverse(), current_camera.inverse()};  // T_cam_obj
  const bt::SurfaceAgreement verifier;
  CHECK(verifier.agreement(graph) == doctest::Approx(1.0));
  CHECK(verifier.accepts(graph, bt::Evidence::SurfaceOnly));
  graph.poses.back() = bt::SE3d(bt::SO3d::exp(Eigen::Vector3d(0, M_PI, 0)), Eigen::Vector3d(0, 0, 2.2)) * graph.poses.back();
  CHECK(verifier.agreement(graph) == 0.0);
  CHECK_FALSE(verifier.accepts(graph, bt::Evidence::Features));
}
