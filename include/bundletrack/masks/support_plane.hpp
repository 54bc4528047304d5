#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/plane_moments.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// The surface the object rests on or leans against in the first frame (a table, the floor, a
/// wall), in the object's frame: distance(p) = n.p + d, the object on the side n points to. A
/// rigid object does not reach through what it touched, so wherever it is carried afterwards
/// every point of it keeps distance >= 0 in its own frame (up to noise); a surface met on that
/// plane later is the support, or lies where the support was, and not the object.
struct SupportPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;

  double distance(const Eigen::Vector3d& p_obj) const { return normal.dot(p_obj) + offset; }
};

/// The pixels around an object's mask that findSupportPlane fits the plane to: from `gap_px` out
/// (the mask's registration error) to half the mask's size (the square root of its area) beyond
/// that, at least 8 pixels; empty for an empty mask.
inline cv::Mat ringAround(const cv::Mat& mask, int gap_px) {
  const int area = cv::countNonZero(mask);
  if (area == 0) return cv::Mat::zeros(mask.size(), CV_8UC1);
  const int ring_px = std::max(8, int(std::lround(0.5 * std::sqrt(double(area)))));
  const auto dilated = [&](int r) {
    cv::Mat out;
    cv::dilate(mask, out, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
    return out;
  };
  return dilated(gap_px + ring_px) & ~dilated(gap_px);
}

/// Finds the support plane in the first frame, if there is one: a plane fitted by RANSAC (three
/// points per hypothesis, a fixed seed) to the readings in a ring around the object's mask,
/// within `tolerance` (widened by the frame's NoiseScale at each reading) and with normals within
/// 45 degrees of its own (the paper's RANSAC normal check), that
/// - holds a quarter of the ring's readings or more (a surface around the object, not a crumb),
/// - has at most 2 % of the object's readings more than `tolerance` behind it (the object lies on
///   one side), and
/// - is reached by the object: 2 % of its readings or more lie within `tolerance` of it (it
///   touches the plane; an object held in front of a wall does not).
/// The best such plane (most inliers) is refitted by least squares over its inliers. `ring` is
/// ringAround(first.mask, gap) for the mask's registration error; first.mask must be the object's
/// (the first frame's given mask).
inline std::optional<SupportPlane> findSupportPlane(const RgbdFrame& first, const SE3d& T_cam_obj, const cv::Mat& ring,
                                                    float tolerance) {
  constexpr double kMinRingFraction = 0.25, kMaxBehindFraction = 0.02, kMinContactFraction = 0.02;
  const float kMinNormalCosine = std::cos(float(std::numbers::pi) / 4.0f);  // RANSAC's 45 degree normal check
  constexpr int kHypotheses = 256, kMinRingPoints = 30, kMaxObjectPoints = 4000;

  struct Reading {
    Eigen::Vector3f p, n;
    float tolerance;
  };
  std::vector<Reading> around, object;
  for (int v = 0; v < first.depth.rows; ++v) {
    for (int u = 0; u < first.depth.cols; ++u) {
      const float z = first.depth.at<float>(v, u);
      if (z <= 0.0f) continue;
      const cv::Vec3f &p = first.points.at<cv::Vec3f>(v, u), &n = first.normals.at<cv::Vec3f>(v, u);
      const Reading reading{{p[0], p[1], p[2]}, {n[0], n[1], n[2]}, first.noise.widen(tolerance, z)};
      if (ring.at<uchar>(v, u)) around.push_back(reading);
      else if (first.mask.at<uchar>(v, u)) object.push_back(reading);
    }
  }
  if (int(around.size()) < kMinRingPoints || object.empty()) return std::nullopt;
  if (object.size() > std::size_t(kMaxObjectPoints)) {  // an even subsample: the fractions stay
    std::vector<Reading> every;
    const double stride = double(object.size()) / kMaxObjectPoints;
    for (int k = 0; k < kMaxObjectPoints; ++k) every.push_back(object[std::size_t(k * stride)]);
    object.swap(every);
  }

  using Plane = Eigen::Hyperplane<float, 3>;
  const auto isInlier = [&](const Plane& plane, const Reading& r) {
    return std::abs(plane.signedDistance(r.p)) <= r.tolerance && std::abs(plane.normal().dot(r.n)) >= kMinNormalCosine;
  };
  // The plane turned to have the object on its positive side, if the object rests on it.
  const auto supporting = [&](Plane plane) -> std::optional<Plane> {
    std::vector<float> distances(object.size());
    for (std::size_t k = 0; k < object.size(); ++k) distances[k] = plane.signedDistance(object[k].p);
    std::vector<float> sorted = distances;
    std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
    const float side = sorted[sorted.size() / 2] < 0.0f ? -1.0f : 1.0f;
    plane.coeffs() *= side;
    std::size_t behind = 0, touching = 0;
    for (std::size_t k = 0; k < object.size(); ++k) {
      behind += side * distances[k] < -object[k].tolerance;
      touching += std::abs(distances[k]) <= object[k].tolerance;
    }
    if (double(behind) > kMaxBehindFraction * double(object.size()) ||
        double(touching) < kMinContactFraction * double(object.size()))
      return std::nullopt;
    return plane;
  };

  std::mt19937 rng(20211001u);
  std::uniform_int_distribution<std::size_t> pick(0, around.size() - 1);
  std::optional<Plane> best;
  std::size_t best_inliers = std::size_t(std::ceil(kMinRingFraction * double(around.size()))) - 1;
  for (int h = 0; h < kHypotheses; ++h) {
    const Eigen::Vector3f a = around[pick(rng)].p, b = around[pick(rng)].p, c = around[pick(rng)].p;
    const Eigen::Vector3f n = (b - a).cross(c - a);
    if (n.norm() < 1e-9f) continue;
    const Plane plane(n.normalized(), a);
    const auto inliers = std::size_t(std::count_if(around.begin(), around.end(), [&](const Reading& r) { return isInlier(plane, r); }));
    if (inliers <= best_inliers) continue;
    if (const auto oriented = supporting(plane)) {
      best = oriented;
      best_inliers = inliers;
    }
  }
  if (!best) return std::nullopt;
  // Least squares over the inliers (centroid and the covariance's least direction): within the
  // tolerance slab the best hypothesis may lie off-centre by up to the tolerance.
  PlaneMoments inliers;
  for (const Reading& r : around)
    if (isInlier(*best, r)) inliers.add(r.p.cast<double>());
  Eigen::Vector3d normal = inliers.normal();
  if (normal.dot(best->normal().cast<double>()) < 0.0) normal = -normal;
  const Eigen::Vector3d centroid = inliers.mean();
  if (const auto refined = supporting(Plane(normal.cast<float>(), centroid.cast<float>()))) best = refined;
  const SE3d T_obj_cam = T_cam_obj.inverse();
  const Eigen::Vector3d n_cam = best->normal().cast<double>(), on_cam = -double(best->offset()) * n_cam;
  const Eigen::Vector3d n_obj = T_obj_cam.rotation() * n_cam;
  return SupportPlane{n_obj, -n_obj.dot(T_obj_cam * on_cam)};
}

}  // namespace bundletrack
