#pragma once

#include <algorithm>
#include <string>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/depth_filter.hpp"
#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/point_map.hpp"

namespace bundletrack {

/// One RGB-D observation, preprocessed. Every image has the colour image's size; depth, points and
/// normals are computed inside `region` only (the whole image unless makeFrame was given less),
/// and are zero (invalid) outside it.
struct RgbdFrame {
  std::string name;  ///< the frame's file stem, e.g. "000042"
  cv::Mat color;  ///< CV_8UC3, BGR
  cv::Mat depth;  ///< CV_32FC1, metres after filterDepth; 0 = invalid
  cv::Mat mask;  ///< CV_8UC1, 255 on the object; empty when no mask is known for this frame
  cv::Mat points;  ///< CV_32FC3, camera-frame points; 0 where depth is invalid
  cv::Mat normals;  ///< CV_32FC3, unit normals facing the camera; 0 where undefined
  NoiseScale noise;  ///< the depth sensor's noise, for tolerances on this frame's depths
  cv::Rect region;  ///< where depth, points and normals were computed
  cv::Rect depth_view;  ///< where the depth camera sees: the bounding box of the raw depth's readings (empty: none)
};

/// One RGB-D observation as decoded, before preprocessing.
struct RawFrame {
  std::string name;
  cv::Mat color;  ///< CV_8UC3, BGR
  cv::Mat depth;  ///< CV_32FC1, metres as measured; 0 = no reading
  cv::Mat mask;  ///< CV_8UC1, empty when the data has no mask for this frame
};

struct FrameSettings {
  DepthFilterSettings depth_filter;
  float normal_max_depth_jump = 0.02f;  ///< metres; see estimateNormals
  DepthNoise sensor = DepthNoise::structuredLight();  ///< widens the depth tolerances (NoiseScale)
};

/// How far (pixels) a preprocessed pixel depends on the raw depth around it: erosion, then each
/// smoothing pass, then the normals' differences.
inline int preprocessingReach(const FrameSettings& s) {
  return s.depth_filter.erode_radius + s.depth_filter.smooth_passes * s.depth_filter.smooth_radius + 1;
}

/// The part of an image of size `image` that makeFrame preprocesses for `region`: the region
/// within the image, or the whole image for an empty region.
inline cv::Rect preprocessedRegion(const cv::Rect& region, cv::Size image) {
  const cv::Rect whole({0, 0}, image);
  return region.area() > 0 ? region & whole : whole;
}

/// The bounding box of a raw depth image's readings (metres, 0: none): where the depth camera
/// sees. A depth image registered to the colour camera covers less of it where the depth camera's
/// view is narrower (the shared sequences: no reading in 15-43 columns and 21-25 rows at each border);
/// within the box a pixel without a reading saw nothing within the sensor's range (or a shadow, or
/// a surface that returns no light). Rows are scanned from each end, then columns within them,
/// each up to its first reading.
inline cv::Rect depthCameraView(const cv::Mat& raw_depth) {
  CV_Assert(raw_depth.type() == CV_32FC1);
  const auto row_has_reading = [&](int y) {
    const float* row = raw_depth.ptr<float>(y);
    return std::any_of(row, row + raw_depth.cols, [](float z) { return z > 0.0f; });
  };
  int top = 0, bottom = raw_depth.rows;
  while (top < bottom && !row_has_reading(top)) ++top;
  while (bottom > top && !row_has_reading(bottom - 1)) --bottom;
  if (top == bottom) return {};
  const auto column_has_reading = [&](int x) {
    for (int y = top; y < bottom; ++y)
      if (raw_depth.at<float>(y, x) > 0.0f) return true;
    return false;
  };
  int left = 0, right = raw_depth.cols;  // rows top and bottom - 1 hold a reading: both loops stop
  while (!column_has_reading(left)) ++left;
  while (!column_has_reading(right - 1)) --right;
  return {left, top, right - left, bottom - top};
}

/// Filters the raw depth (metres) and derives points and normals, the depth tolerances widened by
/// the sensor's noise. With a region (Tracker::regionOfInterest: the object's neighbourhood), only
/// that part of the image is processed, from the raw depth within preprocessingReach of it, so the
/// result inside the region is the one of processing the whole image; outside it is zero.
inline RgbdFrame makeFrame(std::string name, cv::Mat color, const cv::Mat& raw_depth, cv::Mat mask,
                           const PinholeCameraf& camera, const FrameSettings& settings = {}, cv::Rect region = {}) {
  const cv::Rect image({0, 0}, raw_depth.size());
  region = preprocessedRegion(region, image.size());
  const NoiseScale noise(settings.sensor, camera.fx);
  RgbdFrame frame{std::move(name), std::move(color), {}, std::move(mask), {}, {}, noise, region, depthCameraView(raw_depth)};
  const cv::Rect around = grownWithin(region, preprocessingReach(settings), image.size());
  PinholeCameraf shifted = camera;  // pixel (u, v) of the image is (u - around.x, v - around.y) of the crop
  shifted.cx -= float(around.x);
  shifted.cy -= float(around.y);
  const cv::Mat depth = filterDepth(raw_depth(around), settings.depth_filter, noise);
  const cv::Mat points = unprojectDepth(depth, shifted);
  const cv::Mat normals = estimateNormals(points, settings.normal_max_depth_jump, noise);
  if (region == image) {
    frame.depth = depth, frame.points = points, frame.normals = normals;
    return frame;
  }
  const cv::Rect inside = region - around.tl();
  frame.depth = cv::Mat::zeros(image.size(), CV_32FC1);
  frame.points = cv::Mat::zeros(image.size(), CV_32FC3);
  frame.normals = cv::Mat::zeros(image.size(), CV_32FC3);
  depth(inside).copyTo(frame.depth(region));
  points(inside).copyTo(frame.points(region));
  normals(inside).copyTo(frame.normals(region));
  return frame;
}

inline RgbdFrame makeFrame(RawFrame raw, const PinholeCameraf& camera, const FrameSettings& settings = {},
                           cv::Rect region = {}) {
  return makeFrame(std::move(raw.name), std::move(raw.color), raw.depth, std::move(raw.mask), camera, settings, region);
}

}  // namespace bundletrack
