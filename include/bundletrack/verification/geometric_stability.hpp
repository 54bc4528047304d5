#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/surface_grid.hpp"

namespace bundletrack {

/// Grid cells around a point whose normals geometricStability averages, on data as noisy as the
/// reference (NoiseScale 1): a noisy normal tilts a plane's point-to-plane rows into its in-plane
/// directions and makes a plane look stable (normals ~10 degrees off, 0.12 rad per axis: a
/// stability of sigma^2 ~ 0.013, as a mug's); averaging the 5x5 cells around a point divides
/// that by ~25 (tests/test_geometric_stability.cpp). The window grows with the grid's noise scale,
/// so that the averaged normals are as noisy at any depth and from any sensor.
inline constexpr int kStabilityNormalRadius = 2;

/// lambda_min / lambda_max of a 6x6 twist information: 0 when a direction is free (or for no
/// information at all), up to 1 when every direction is held alike.
inline double evenness(const Eigen::Matrix<double, 6, 6>& information) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(
      information.selfadjointView<Eigen::Lower>(), Eigen::EigenvaluesOnly);
  const Eigen::Matrix<double, 6, 1>& values = eigen.eigenvalues();  // ascending
  return values(5) > 0.0 ? std::max(0.0, values(0)) / values(5) : 0.0;
}

/// The centroid of a surface's points and their RMS distance from it (camera frame).
struct SurfaceSpread {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double rms_radius = 0.0;
};

inline SurfaceSpread spreadOf(const SurfaceGrid& surface) {
  SurfaceSpread spread;
  if (surface.cells.empty()) return spread;
  for (const cv::Point& cell : surface.cells) {
    const cv::Vec3f& p = surface.point(cell);
    spread.centroid += Eigen::Vector3d(p[0], p[1], p[2]);
  }
  spread.centroid /= double(surface.cells.size());
  double squared_radius = 0.0;
  for (const cv::Point& cell : surface.cells) {
    const cv::Vec3f& p = surface.point(cell);
    squared_radius += (Eigen::Vector3d(p[0], p[1], p[2]) - spread.centroid).squaredNorm();
  }
  spread.rms_radius = std::sqrt(squared_radius / double(surface.cells.size()));
  return spread;
}

/// How well a surface alone pins down a rigid motion under a point-to-plane term (the geometric
/// stability of Gelfand et al., "Geometrically stable sampling for the ICP algorithm", 3DIM 2003):
/// each point p with normal n constrains the twist (t, w) by n.t + ((p - c) / r x n).w, with c the
/// centroid and r the points' RMS distance from it (rotations as displacements at the surface's
/// size), n the mean normal of the cells within `radius` cells (kStabilityNormalRadius times the
/// noise scale, rounded up, by default). Returns lambda_min / lambda_max of the 6x6 information
/// sum J^T J: 0 for a plane (sliding and spinning in it are free), a sphere (any rotation) or a
/// surface of revolution (its twist), up to 1 when every direction is held alike; 0 for fewer
/// than 6 points.
inline double geometricStability(const SurfaceGrid& surface, int radius = -1) {
  if (surface.cells.size() < 6) return 0.0;
  if (radius < 0) radius = int(std::ceil(kStabilityNormalRadius * surface.noise_scale));
  const auto [centroid, rms_radius] = spreadOf(surface);
  if (!(rms_radius > 0.0)) return 0.0;
  cv::Rect box(surface.cells.front(), cv::Size(1, 1));
  for (const cv::Point& cell : surface.cells) box |= cv::Rect(cell, cv::Size(1, 1));
  // Sums of the normals over each cell's window (cells without a point hold zero).
  cv::Mat sums;
  cv::boxFilter(surface.normals(box - surface.origin), sums, CV_32F, cv::Size(2 * radius + 1, 2 * radius + 1), cv::Point(-1, -1),
                false, cv::BORDER_CONSTANT);
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  for (const cv::Point& cell : surface.cells) {
    const cv::Vec3f& p = surface.point(cell);
    const cv::Vec3f& s = sums.at<cv::Vec3f>(cell - box.tl());
    const Eigen::Vector3d normal = Eigen::Vector3d(s[0], s[1], s[2]).normalized();
    Eigen::Matrix<double, 6, 1> row;
    row << normal, ((Eigen::Vector3d(p[0], p[1], p[2]) - centroid) / rms_radius).cross(normal);
    information.selfadjointView<Eigen::Lower>().rankUpdate(row);
  }
  return evenness(information);
}

/// How evenly everything the pose graph weighs holds one node's pose: `information` is the
/// node's 6x6 block of the Gauss-Newton matrix (its right perturbation T_cam_obj exp(d), d =
/// (translation, rotation) in the object frame, turning about the object's origin), taken as
/// geometricStability takes a surface's: re-centred on the object's points (`centroid`, object
/// frame: a turn about the origin far from the points is mostly a shift) and with rotations as
/// displacements at their RMS radius, then lambda_min / lambda_max. With d = M d', M = [I [c]x;
/// 0 I] (a turn phi about c moves a by phi x (a - c) = phi x a - phi x c), the information of d'
/// is M^T H M; dividing the rotation rows and columns by the radius scales them. ~0 where the
/// data leave a direction free (a textureless mug's turn about its axis with the handle hidden).
inline double poseStability(const Eigen::Matrix<double, 6, 6>& information, const Eigen::Vector3d& centroid,
                            double rms_radius) {
  if (!(rms_radius > 0.0)) return 0.0;
  Eigen::Matrix<double, 6, 6> recentre = Eigen::Matrix<double, 6, 6>::Identity();
  recentre.topRightCorner<3, 3>() << 0.0, -centroid.z(), centroid.y(), centroid.z(), 0.0, -centroid.x(), -centroid.y(),
      centroid.x(), 0.0;
  Eigen::Matrix<double, 6, 1> scale;
  scale << 1.0, 1.0, 1.0, 1.0 / rms_radius, 1.0 / rms_radius, 1.0 / rms_radius;
  const Eigen::Matrix<double, 6, 6> symmetric = 0.5 * (information + information.transpose());
  return evenness(scale.asDiagonal() * (recentre.transpose() * symmetric * recentre) * scale.asDiagonal());
}

}  // namespace bundletrack
