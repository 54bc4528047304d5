#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/depth_filter.hpp"
#include "bundletrack/core/depth_noise.hpp"
#include "bundletrack/core/point_map.hpp"

namespace bundletrack {

/// One RGB-D observation, preprocessed. Every image has the colour image's size.
struct RgbdFrame {
  std::string name;  ///< the frame's file stem, e.g. "000042"
  cv::Mat color;  ///< CV_8UC3, BGR
  cv::Mat depth;  ///< CV_32FC1, metres after filterDepth; 0 = invalid
  cv::Mat mask;  ///< CV_8UC1, 255 on the object; empty when no mask is known for this frame
  cv::Mat points;  ///< CV_32FC3, camera-frame points; 0 where depth is invalid
  cv::Mat normals;  ///< CV_32FC3, unit normals facing the camera; 0 where undefined
  NoiseScale noise;  ///< the depth sensor's noise, for tolerances on this frame's depths
};

struct FrameSettings {
  DepthFilterSettings depth_filter;
  float normal_max_depth_jump = 0.02f;  ///< metres; see estimateNormals
  DepthNoise sensor = DepthNoise::structuredLight();  ///< widens the depth tolerances (NoiseScale)
};

/// Filters the raw depth (metres) and derives points and normals, the depth tolerances widened by
/// the sensor's noise.
inline RgbdFrame makeFrame(std::string name, cv::Mat color, const cv::Mat& raw_depth, cv::Mat mask,
                           const PinholeCameraf& camera, const FrameSettings& settings = {}) {
  const NoiseScale noise(settings.sensor, camera.fx);
  RgbdFrame frame{std::move(name), std::move(color), filterDepth(raw_depth, settings.depth_filter, noise),
                  std::move(mask), {}, {}, noise};
  frame.points = unprojectDepth(frame.depth, camera);
  frame.normals = estimateNormals(frame.points, settings.normal_max_depth_jump, noise);
  return frame;
}

}  // namespace bundletrack
