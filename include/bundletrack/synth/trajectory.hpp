#pragma once

#include <cmath>
#include <numbers>

#include "bundletrack/core/se3.hpp"

namespace bundletrack::synth {

/// World frame of the synthetic scenes: z up, the table is the plane z = 0.

/// Camera at `eye` looking at `target` with the image's up direction towards world +z
/// (camera axes: x right, y down, z forward).
inline SE3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d R_world_cam;
  R_world_cam.col(0) = right;
  R_world_cam.col(1) = forward.cross(right);
  R_world_cam.col(2) = forward;
  return SE3d(SO3d::fromMatrix(R_world_cam), eye);
}

/// Phase of the periodic motions: at speed 1 one period takes 300 frames.
inline double motionPhase(double frame, double speed) { return speed * frame * 2.0 * std::numbers::pi / 300.0; }

/// YCBInEOAT-like: static camera, the object carried in front of it by a hand. It turns about the
/// vertical by theta = 90 deg (1 - cos phase), i.e. 0 -> 180 -> 0 deg per period (at most 1.9 deg
/// per frame at speed 1), wobbles by up to 11 deg about the other axes and drifts by a few cm.
struct HandHeldMotion {
  Eigen::Vector3d centre = Eigen::Vector3d(0.0, 0.0, 0.25);
  Eigen::Vector3d eye = Eigen::Vector3d(0.0, -0.7, 0.45);  ///< 0.73 m from the centre
  SE3d T_world_cam = lookAt(eye, centre);

  /// The camera on the same line of sight, `distance` metres from the centre.
  SE3d cameraAt(double distance) const { return lookAt(centre + distance * (eye - centre).normalized(), centre); }

  SE3d T_world_obj(double frame, double speed) const {
    const double phase = motionPhase(frame, speed);
    const double turn = 0.5 * std::numbers::pi * (1.0 - std::cos(phase));
    const Eigen::Vector3d wobble(0.2 * std::sin(2.0 * phase), 0.2 * std::sin(3.0 * phase), 0.0);
    const SO3d R = SO3d::exp(turn * Eigen::Vector3d::UnitZ()) * SO3d::exp(wobble) *
                   SO3d::exp(Eigen::Vector3d(0.35, 0.0, 0.0));  // initial tilt shows the top
    const Eigen::Vector3d drift(0.07 * std::sin(phase), 0.04 * std::sin(2.0 * phase), 0.04 * std::sin(1.5 * phase));
    return SE3d(R, centre + drift);
  }
};

/// NOCS-like: the object rests on the table and the camera orbits it, half a turn per period, at
/// a distance of 0.5-0.7 m and a varying height.
struct CameraOrbitMotion {
  SE3d T_world_cam(double frame, double speed, const Eigen::Vector3d& target) const {
    const double phase = motionPhase(frame, speed);
    const double azimuth = -0.5 * std::numbers::pi + 0.5 * phase;
    const double radius = 0.6 + 0.1 * std::sin(phase), height = 0.35 + 0.1 * std::sin(0.7 * phase);
    const Eigen::Vector3d eye(radius * std::cos(azimuth), radius * std::sin(azimuth), height);
    return lookAt(eye, target + Eigen::Vector3d(0.02 * std::sin(1.3 * phase), 0.0, 0.0));
  }
};

}  // namespace bundletrack::synth
