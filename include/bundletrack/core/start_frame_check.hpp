#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/error.hpp"
#include "bundletrack/core/se3.hpp"

namespace bundletrack {

/// How far the object's visible surface may lie from its origin's depth, as a factor either way.
/// The origin of an object's frame lies on or inside the object (CAD models; the annotations of
/// YCB-Video, YCBInEOAT and BOP), so the surface in front of it is nearer than the origin by at most
/// the object's depth: a factor of 2 allows an object as deep as it is far from the camera.
inline constexpr double kStartDepthFactor = 2.0;

/// The first frame must show the object's surface: depth readings under its mask (after
/// filtering, which drops readings outside depth.min_depth - depth.max_depth). A start pose
/// T_cam_obj places the object's origin at depth t_z, and the depth under the mask reads its
/// visible surface. Where their median differs from t_z by more than kStartDepthFactor either way,
/// the depth and the pose are in different units -- the mistake no range test sees when a near
/// scene read 5 times too far still lies in the sensor's range -- and the error names the likely
/// factor. The identity (no pose known: the origin at the camera) is not compared; an origin
/// behind the camera is refused. Without a mask there is nothing to check.
inline void checkStartFrame(const cv::Mat& depth, const cv::Mat& mask, const SE3d& T_cam_obj, const std::string& frame) {
  if (mask.empty() || cv::countNonZero(mask) == 0) return;
  std::vector<float> readings;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u)
      if (mask.at<uchar>(v, u) && depth.at<float>(v, u) > 0.0f) readings.push_back(depth.at<float>(v, u));
  if (readings.empty())
    throw InputError("frame " + frame, "no depth reading under the object's mask (readings nearer than depth.min_depth "
                                       "or farther than depth.max_depth are dropped): the track cannot start without "
                                       "the object's surface");
  if (T_cam_obj.translation().isZero(0.0)) return;
  const double origin_depth = T_cam_obj.translation().z();
  char numbers[160];
  if (origin_depth <= 0.0) {
    std::snprintf(numbers, sizeof(numbers), "%.3f %.3f %.3f m", T_cam_obj.translation().x(), T_cam_obj.translation().y(),
                  origin_depth);
    throw InputError("frame " + frame, std::string("the start pose puts the object's origin at ") + numbers +
                                           ", behind the camera (T_cam_obj maps object points into the camera frame: "
                                           "is it the inverse, T_obj_cam?)");
  }
  std::nth_element(readings.begin(), readings.begin() + std::ptrdiff_t(readings.size() / 2), readings.end());
  const double surface_depth = readings[readings.size() / 2];
  const double factor = surface_depth / origin_depth;
  if (factor <= kStartDepthFactor && factor >= 1.0 / kStartDepthFactor) return;
  std::snprintf(numbers, sizeof(numbers), "%.3f m, the depth under its mask %.3f m (%.2f times as far)", origin_depth,
                surface_depth, factor);
  std::string hint = "the depth scale is probably wrong (depth.scale: metres per unit of the depth images)";
  for (const int common : {5, 10})
    for (const bool far : {true, false})
      if (std::abs((far ? factor : 1.0 / factor) / common - 1.0) < 0.25)
        hint = "the depth reads " + std::to_string(common) + (far ? " times too far" : " times too near") +
               ": depth.scale is probably " + std::to_string(common) + (far ? " times too large" : " times too small") +
               " (images in millimetres need 0.001, in 0.1 mm 0.0001, TUM RGB-D's 1/5000 0.0002)";
  throw InputError("frame " + frame, std::string("the start pose puts the object's origin at depth ") + numbers + ": " +
                                         hint + ", or the pose is not this frame's");
}

}  // namespace bundletrack
