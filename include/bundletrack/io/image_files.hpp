#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/error.hpp"
#include "bundletrack/io/file_access.hpp"
#include "bundletrack/io/png_decoder.hpp"

namespace bundletrack::io {

inline std::string describeImageType(const cv::Mat& image) {
  const int depth = image.depth();
  const char* bits = depth == CV_8U || depth == CV_8S     ? "8-bit"
                     : depth == CV_16U || depth == CV_16S ? "16-bit"
                     : depth == CV_32F || depth == CV_32S ? "32-bit"
                                                          : "64-bit";
  return std::string(bits) + " with " + std::to_string(image.channels()) + " channel(s)";
}

/// Whether an encoded JPEG or PNG ends as its format requires: a JPEG with its end-of-image
/// marker FF D9 (entropy-coded data never holds it: a 0xFF there is followed by 0x00), a PNG with
/// its IEND chunk, either within the last 1 KiB (padding may follow). A truncated file lacks it,
/// and decoders still return an image whose rest is grey or black. Other formats: true.
inline bool endsComplete(const std::vector<uchar>& bytes) {
  const auto startsWith = [&](std::initializer_list<uchar> magic) {
    return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
  };
  const auto tailHolds = [&](std::initializer_list<uchar> marker) {
    const auto tail = bytes.end() - std::ptrdiff_t(std::min<std::size_t>(bytes.size(), 1024));
    return std::search(tail, bytes.end(), marker.begin(), marker.end()) != bytes.end();
  };
  if (startsWith({0xFF, 0xD8, 0xFF})) return tailHolds({0xFF, 0xD9});
  if (startsWith({0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A})) return tailHolds({'I', 'E', 'N', 'D'});
  return true;
}

/// Whether the bytes start as a PNG or a JPEG file does.
inline bool isPngOrJpeg(const std::vector<uchar>& bytes) {
  const auto startsWith = [&](std::initializer_list<uchar> magic) {
    return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
  };
  return startsWith({0xFF, 0xD8, 0xFF}) || startsWith({0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A});
}

/// Decodes an encoded image (the bytes of `path`); an empty, truncated or undecodable one is an
/// InputError, and so is any format but PNG and JPEG (the layouts' formats): OpenCV picks a
/// decoder by the content, and some abort the process on malformed input (its DICOM reader
/// asserts, found by fuzz_sequence_files). The PNG layouts of RGB-D recordings go through
/// decodePng (the same pixels, in half the time), the rest through cv::imdecode.
inline cv::Mat decodeImage(const std::vector<uchar>& bytes, int flags, const std::filesystem::path& path) {
  if (bytes.empty()) throw InputError(path, "empty file");
  if (!isPngOrJpeg(bytes)) throw InputError(path, "not a PNG or JPEG image (images must be .png or .jpg)");
  if (!endsComplete(bytes))
    throw InputError(path, "truncated or corrupt image: it ends without its format's end marker (" +
                               std::to_string(bytes.size()) + " bytes)");
  PngDecoding png = decodePng(bytes, flags);
  if (!png.error.empty()) throw InputError(path, "corrupt PNG image: " + png.error);
  if (!png.image.empty()) return png.image;
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, flags);
  } catch (const cv::Exception& error) {
    throw InputError(path, "cannot decode image (" + std::string(error.err) + ")");
  }
  if (image.empty()) throw InputError(path, "cannot decode image");
  return image;
}

/// Decodes an image file; a missing or unreadable file is an InputError too.
inline cv::Mat readImage(const std::filesystem::path& path, int flags) {
  std::ifstream in = openForReading(path, std::ios::binary);
  std::vector<uchar> bytes;
  std::error_code unknown_size;
  if (const std::uintmax_t size = std::filesystem::file_size(path, unknown_size); !unknown_size) bytes.reserve(size);
  char block[1 << 16];  // read in blocks: a file's size may change, or be unknown (a pipe)
  while (in.read(block, sizeof(block)) || in.gcount() > 0) bytes.insert(bytes.end(), block, block + in.gcount());
  return decodeImage(bytes, flags, path);
}

/// 8-bit BGR colour.
inline cv::Mat readColor(const std::filesystem::path& path) { return readImage(path, cv::IMREAD_COLOR); }

/// Depth in metres (CV_32FC1) from a decoded single-channel 16-bit image (of `path`) times `scale`
/// (metres per unit). Only the encoding is checked here; an all-zero image is the caller's decision.
inline cv::Mat depthFromImage(const cv::Mat& raw, double scale, const std::filesystem::path& path) {
  if (raw.type() != CV_16UC1)
    throw InputError(path, "depth must be a single-channel 16-bit image, got " + describeImageType(raw));
  cv::Mat metres;
  raw.convertTo(metres, CV_32F, scale);
  return metres;
}

/// The commonest mistake with a new dataset is the depth unit. A depth map read with the wrong
/// unit is a valid depth map of the scene scaled (shape and angles are kept), so only ranges can
/// tell: the object's median depth (metres, `depth` under `mask`) must lie between 5 cm and 20 m,
/// the range of any RGB-D sensor, and the median depth of the whole frame within twice
/// `max_range`, the farthest depth the sensor's specification covers (DepthNoise::max_range;
/// 0: not checked). Twice, because sensors report beyond their specified range and a room's far
/// wall may lie there; an object 1 m away read in 0.1 mm units with millimetres' 0.001 seems 10 m
/// away. A frame median beyond max_range itself but within twice it is returned as a caution (the
/// caller shows it; empty: none): 0.2 mm units read as millimetres put a scene whose median is
/// 0.8-1.6 m there, and the sensor's noise is unspecified there anyway. Scenes nearer than that
/// read five times too far cannot be told from real far ones by ranges (a start pose can tell:
/// checkStartFrame). `scale` is the unit the depth was read with, `source` names the depth in the
/// messages.
[[nodiscard]] inline std::string checkDepthScale(const cv::Mat& depth, const cv::Mat& mask, double scale,
                                                 const std::filesystem::path& source, double max_range = 0.0) {
  const auto median = [&](bool whole_frame) {
    std::vector<float> values;
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u)
        if ((whole_frame || mask.at<uchar>(v, u)) && depth.at<float>(v, u) > 0.0f) values.push_back(depth.at<float>(v, u));
    if (values.empty()) return 0.0;
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
    return double(values[values.size() / 2]);
  };
  const double object = median(false);
  if (object == 0.0) throw InputError(source, "no valid depth under the first frame's object mask");
  const std::string with_scale = " with depth scale " + std::to_string(scale) + " m/unit";
  const std::string stated = "median object depth is " + std::to_string(object) + " m" + with_scale;
  if (object < 0.05)
    throw InputError(source, stated + ": closer than any RGB-D sensor measures; the depth scale is probably too small"
                                      " (images in millimetres need 0.001, in 0.1 mm 0.0001)");
  if (object > 20.0)
    throw InputError(source, stated + ": farther than any RGB-D sensor measures; the depth scale is probably too large"
                                      " (images in millimetres need 0.001, not 1)");
  if (max_range <= 0.0) return {};
  const double frame = median(true);
  if (frame <= max_range) return {};
  char range[32];
  std::snprintf(range, sizeof(range), "%.2f", max_range);
  const std::string beyond = "median depth of the whole first frame is " + std::to_string(frame) + " m" + with_scale +
                             ", more than " + (frame > 2.0 * max_range ? "twice " : "") + "the " + range +
                             " m that the sensor (sensor.model) is specified for: ";
  if (frame > 2.0 * max_range)
    throw InputError(source, beyond + "the depth scale is probably too large (images in 0.1 mm need 0.0001, TUM "
                                      "RGB-D's 1/5000 0.0002) or sensor.model names another sensor");
  return source.string() + ": " + beyond + "if the images are in finer units than the scale says (0.2 mm or "
         "TUM RGB-D's 1/5000: 0.0002; 0.1 mm: 0.0001), set depth.scale; if sensor.model names another sensor, set "
         "it; otherwise expect noise beyond the sensor's specification";
}

/// The depth of an image file (depthFromImage).
inline cv::Mat readDepth(const std::filesystem::path& path, double scale) {
  return depthFromImage(readImage(path, cv::IMREAD_UNCHANGED), scale, path);
}

/// Binary mask (CV_8UC1, 0 or 255) of a decoded image: any non-zero pixel, of any channel, is on
/// the object.
inline cv::Mat maskFromImage(const cv::Mat& raw) {
  if (raw.channels() > 1) {
    std::vector<cv::Mat> channels;
    cv::split(raw, channels);
    cv::Mat any = channels[0] != 0;
    for (std::size_t c = 1; c < channels.size(); ++c) any |= channels[c] != 0;
    return any;
  }
  return raw != 0;
}

/// The binary mask of an image file (maskFromImage).
inline cv::Mat readMask(const std::filesystem::path& path) { return maskFromImage(readImage(path, cv::IMREAD_UNCHANGED)); }

}  // namespace bundletrack::io
