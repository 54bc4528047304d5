#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "bundletrack/residuals/pair_system.hpp"

namespace bundletrack {

/// Paper eq. 3: dense point-to-plane distances by projective association on the downsampled grid.
/// A point p_s of frame s is moved into frame t (T_t T_s^-1 p_s), projected, and paired with the
/// point p_t seen at that pixel; the pair counts when it lies within max_distance and its normals
/// within max_normal_angle_deg. The residual, in the object frame with m = R_s^T n_s,
///   r = m . (T_t^-1 p_t - T_s^-1 p_s),
/// has dr/dd_s = [m^T, (b x m)^T] with b = T_t^-1 p_t, and dr/dd_t = -dr/dd_s (it depends on the
/// relative pose only). Both directions of an edge are summed, as eq. 1 sums over ordered pairs.
struct DensePointToPlane {
  float max_distance = 0.02f;  ///< metres (original code: 2 cm)
  float max_normal_angle_deg = 45.0f;

  template <RobustLoss Loss>
  void linearise(const PairInput& in, const Loss& loss, double weight, PairSystem& system) const {
    addDirected(in.i, in.j, in.T_i, in.T_j, in.grid_camera, loss, weight, false, system);
    addDirected(in.j, in.i, in.T_j, in.T_i, in.grid_camera, loss, weight, true, system);
    system.finish();
  }

 private:
  template <typename Loss>
  void addDirected(const Keyframe& s, const Keyframe& t, const SE3d& T_s, const SE3d& T_t,
                   const PinholeCameraf& camera, const Loss& loss, double weight, bool swapped,
                   PairSystem& system) const {
    // Rigid maps as matrices: the loop applies each to every point.
    const auto affine = [](const SE3d& T) { return Eigen::Isometry3d(T.matrix()); };
    const Eigen::Isometry3d T_s_inv = affine(T_s.inverse()), T_t_inv = affine(T_t.inverse());
    const Eigen::Isometry3d T_t_s = affine(T_t * T_s.inverse()), T_s_t = affine(T_s * T_t.inverse());
    const Eigen::Matrix3d R_s_inv = T_s_inv.linear(), R_s_t = T_s_t.linear();
    const double cos_max = std::cos(double(max_normal_angle_deg) * std::numbers::pi / 180.0);
    const double max_sq = double(max_distance) * double(max_distance);
    for (const cv::Point& cell : s.surface) {
      const cv::Vec3f& ps = s.points.at<cv::Vec3f>(cell);
      const Eigen::Vector3d p_s(ps[0], ps[1], ps[2]);
      const Eigen::Vector3d in_t = T_t_s * p_s;
      if (in_t.z() <= 0.0) continue;
      const int u = int(std::lround(camera.fx * in_t.x() / in_t.z() + camera.cx));
      const int v = int(std::lround(camera.fy * in_t.y() / in_t.z() + camera.cy));
      if (u < 0 || v < 0 || u >= t.points.cols || v >= t.points.rows) continue;
      const cv::Vec3f& pt = t.points.at<cv::Vec3f>(v, u);
      if (pt[2] <= 0.0f) continue;
      const Eigen::Vector3d p_t(pt[0], pt[1], pt[2]);
      if ((T_s_t * p_t - p_s).squaredNorm() > max_sq) continue;
      const cv::Vec3f& ns = s.normals.at<cv::Vec3f>(cell);
      const cv::Vec3f& nt = t.normals.at<cv::Vec3f>(v, u);
      const Eigen::Vector3d n_s(ns[0], ns[1], ns[2]);
      if ((R_s_t * Eigen::Vector3d(nt[0], nt[1], nt[2])).dot(n_s) < cos_max) continue;
      const Eigen::Vector3d m = R_s_inv * n_s, a = T_s_inv * p_s, b = T_t_inv * p_t;
      Eigen::Matrix<double, 1, 6> J_s;
      J_s.leftCols<3>() = m.transpose();
      J_s.rightCols<3>() = b.cross(m).transpose();
      // J_i is J_s, or -J_s when s is the edge's second node.
      system.addRelative(m.dot(b - a), swapped ? Eigen::Matrix<double, 1, 6>(-J_s) : J_s, loss, weight);
    }
  }
};

}  // namespace bundletrack
