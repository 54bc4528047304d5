#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/error.hpp"

namespace bundletrack::io {

inline std::string describeImageType(const cv::Mat& image) {
  const int depth = image.depth();
  const char* bits = depth == CV_8U || depth == CV_8S     ? "8-bit"
                     : depth == CV_16U || depth == CV_16S ? "16-bit"
                     : depth == CV_32F || depth == CV_32S ? "32-bit"
                                                          : "64-bit";
  return std::string(bits) + " with " + std::to_string(image.channels()) + " channel(s)";
}

inline cv::Mat readImage(const std::filesystem::path& path, int flags) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path, "file not found");
  cv::Mat image = cv::imread(path.string(), flags);
  if (image.empty()) throw InputError(path, "cannot decode image");
  return image;
}

/// 8-bit BGR colour.
inline cv::Mat readColor(const std::filesystem::path& path) { return readImage(path, cv::IMREAD_COLOR); }

/// Depth in metres (CV_32FC1) from a single-channel 16-bit image times `scale` (metres per unit).
/// Only the encoding is checked here; an all-zero image is the caller's decision.
inline cv::Mat readDepth(const std::filesystem::path& path, double scale) {
  const cv::Mat raw = readImage(path, cv::IMREAD_UNCHANGED);
  if (raw.type() != CV_16UC1)
    throw InputError(path, "depth must be a single-channel 16-bit image, got " + describeImageType(raw));
  cv::Mat metres;
  raw.convertTo(metres, CV_32F, scale);
  return metres;
}

/// Binary mask (CV_8UC1, 0 or 255): any non-zero pixel, of any channel, is on the object.
inline cv::Mat readMask(const std::filesystem::path& path) {
  cv::Mat raw = readImage(path, cv::IMREAD_UNCHANGED);
  if (raw.channels() > 1) {
    std::vector<cv::Mat> channels;
    cv::split(raw, channels);
    cv::Mat any = channels[0] != 0;
    for (std::size_t c = 1; c < channels.size(); ++c) any |= channels[c] != 0;
    return any;
  }
  return raw != 0;
}

}  // namespace bundletrack::io
