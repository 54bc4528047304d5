#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/error.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// How far the object's visible surface may lie from its origin's depth, as a factor either way.
/// The origin of an object's frame lies on or inside the object (CAD models; the annotations of
/// YCB-Video, YCBInEOAT and BOP), so the surface in front of it is nearer than the origin by at most
/// the object's depth: a factor of 2 allows an object as deep as it is far from the camera.
inline constexpr double kStartDepthFactor = 2.0;

/// Degrees: the least span of a mask that checkStartFrame's test beside the mask allows for (a
/// mask of a few pixels says little of where the object's middle is; 10 cm at 3 m spans 1.9).
inline constexpr double kStartMinSpanDeg = 1.0;

/// The first frame must show the object's surface: depth readings under its mask (after
/// filtering, which drops readings outside depth.min_depth - depth.max_depth). A start pose
/// T_cam_obj must agree with them:
/// - its origin in front of the camera;
/// - seen from the camera, on the object: an origin on or inside the object lies on a ray through
///   its silhouette, so it may lie beside the mask's box of rays by at most the box's size (the
///   mask may cover only part of the object), or kStartMinSpanDeg for a tiny mask;
/// - at the depth of the object: its depth t_z and the median depth under the mask (the visible
///   surface) differ by at most kStartDepthFactor either way. Otherwise the depth and the pose
///   are in different units -- the mistake no range test sees when a near scene read 5 times too
///   far still lies in the sensor's range -- and the error names the likely factor.
/// The identity (no pose known: the origin at the camera) is not compared. Without a mask there is
/// nothing to check.
inline void checkStartFrame(const RgbdFrame& frame, const SE3d& T_cam_obj) {
  if (frame.mask.empty() || cv::countNonZero(frame.mask) == 0) return;
  std::vector<float> readings;
  // The box of the rays (x / z, y / z) through the points under the mask.
  Eigen::Array2d low = Eigen::Array2d::Constant(HUGE_VAL), high = -low;
  for (int v = 0; v < frame.points.rows; ++v)
    for (int u = 0; u < frame.points.cols; ++u) {
      const cv::Vec3f& p = frame.points.at<cv::Vec3f>(v, u);
      if (!frame.mask.at<uchar>(v, u) || p[2] <= 0.0f) continue;
      readings.push_back(p[2]);
      const Eigen::Array2d ray(p[0] / p[2], p[1] / p[2]);
      low = low.min(ray), high = high.max(ray);
    }
  const std::string source = "frame " + frame.name;
  if (readings.empty())
    throw InputError(source, "no depth reading under the object's mask (readings nearer than depth.min_depth "
                             "or farther than depth.max_depth are dropped): the track cannot start without "
                             "the object's surface");
  if (T_cam_obj.translation().isZero(0.0)) return;
  const Eigen::Vector3d origin = T_cam_obj.translation();
  char numbers[200];
  if (origin.z() <= 0.0) {
    std::snprintf(numbers, sizeof(numbers), "%.3f %.3f %.3f m", origin.x(), origin.y(), origin.z());
    throw InputError(source, std::string("the start pose puts the object's origin at ") + numbers +
                                 ", behind the camera (T_cam_obj maps object points into the camera frame: "
                                 "is it the inverse, T_obj_cam?)");
  }
  const double size = std::max((high - low).maxCoeff(), std::tan(radians(kStartMinSpanDeg)));
  const Eigen::Array2d ray(origin.x() / origin.z(), origin.y() / origin.z());
  const double off = std::max((low - ray).maxCoeff(), (ray - high).maxCoeff());
  if (off > size) {
    std::snprintf(numbers, sizeof(numbers), "%.1f degrees beside the object's mask, which spans %.1f degrees",
                  degrees(std::atan(off)), degrees(std::atan(size)));
    throw InputError(source, std::string("the start pose puts the object's origin ") + numbers +
                                 ": an origin on the object lies within the mask's span of it; is the pose another "
                                 "frame's, or T_obj_cam rather than T_cam_obj?");
  }
  std::nth_element(readings.begin(), readings.begin() + std::ptrdiff_t(readings.size() / 2), readings.end());
  const double surface_depth = readings[readings.size() / 2];
  const double factor = surface_depth / origin.z();
  if (factor <= kStartDepthFactor && factor >= 1.0 / kStartDepthFactor) return;
  std::snprintf(numbers, sizeof(numbers), "%.3f m, the depth under its mask %.3f m (%.2f times as far)", origin.z(),
                surface_depth, factor);
  std::string hint = "the depth scale is probably wrong (depth.scale: metres per unit of the depth images)";
  for (const int common : {5, 10})
    for (const bool far : {true, false})
      if (std::abs((far ? factor : 1.0 / factor) / common - 1.0) < 0.25)
        hint = "the depth reads " + std::to_string(common) + (far ? " times too far" : " times too near") +
               ": depth.scale is probably " + std::to_string(common) + (far ? " times too large" : " times too small") +
               " (images in millimetres need 0.001, in 0.1 mm 0.0001, TUM RGB-D's 1/5000 0.0002)";
  throw InputError(source, std::string("the start pose puts the object's origin at depth ") + numbers + ": " + hint +
                               ", or the pose is not this frame's");
}

}  // namespace bundletrack
