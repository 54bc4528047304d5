#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/io/image_files.hpp"
#include "bundletrack/io/intrinsics_file.hpp"
#include "bundletrack/io/point_files.hpp"
#include "bundletrack/io/pose_files.hpp"

namespace bundletrack::io {

struct SequenceSettings {
  double depth_scale = 0.001;  ///< metres per unit of the 16-bit depth images (0.001: millimetres)
  FrameSettings frame;
};

/// The frames of a sequence: its colour images (rgb/*.png, *.jpg) in name order, numeric names
/// compared as numbers. Throws InputError without any, or for two images of one name.
struct ColorImages {
  std::vector<std::string> names;  ///< file stems: the frames' names
  std::vector<std::string> files;  ///< file names in rgb/
};

inline ColorImages listColorImages(const std::filesystem::path& root) {
  const auto numericName = [](const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
  };
  const auto dir = root / "rgb";
  if (!std::filesystem::is_directory(dir)) throw InputError(dir, "directory not found");
  ColorImages found;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) {
      found.names.push_back(entry.path().stem().string());
      found.files.push_back(entry.path().filename().string());
    }
  }
  if (found.names.empty()) throw InputError(dir, "no .png or .jpg colour images");
  std::vector<std::size_t> order(found.names.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const std::string &x = found.names[a], &y = found.names[b];
    if (numericName(x) && numericName(y) && x.size() != y.size()) return x.size() < y.size();
    return x < y;
  });
  ColorImages sorted;
  for (const std::size_t i : order) {
    if (!sorted.names.empty() && sorted.names.back() == found.names[i])
      throw InputError(dir, "two colour images share the name '" + found.names[i] + "'");
    sorted.names.push_back(found.names[i]);
    sorted.files.push_back(found.files[i]);
  }
  return sorted;
}

/// A sequence folder in the YCBInEOAT layout:
///   rgb/<name>.png|jpg   colour          depth/<name>.png   uint16 depth
///   masks/<name>.png     object mask     (the first frame's is required, later ones optional)
///   cam_K.txt            3x3 intrinsics  annotated_poses/<name>.txt  4x4 T_cam_obj (optional)
///   model/points.xyz     object points in the object frame (optional)
/// Frames are the colour images in name order (numeric names compared as numbers).
class YcbineoatSequence {
 public:
  explicit YcbineoatSequence(std::filesystem::path root, SequenceSettings settings = {})
      : root_(std::move(root)), settings_(std::move(settings)) {
    if (!std::filesystem::is_directory(root_)) throw InputError(root_, "sequence directory not found");
    if (!(settings_.depth_scale > 0.0)) throw InputError(root_, "depth scale must be positive");
    ColorImages images = listColorImages(root_);
    names_ = std::move(images.names);
    color_files_ = std::move(images.files);
    camera_ = readIntrinsics(root_ / "cam_K.txt");
    if (!std::filesystem::is_directory(root_ / "depth")) throw InputError(root_ / "depth", "directory not found");

    const cv::Mat first_color = readColor(colorPath(0));
    image_size_ = first_color.size();
    if (camera_.cx < 0.0 || camera_.cx >= image_size_.width || camera_.cy < 0.0 || camera_.cy >= image_size_.height)
      throw InputError(root_ / "cam_K.txt", "principal point (" + std::to_string(camera_.cx) + ", " +
                                                std::to_string(camera_.cy) + ") lies outside the " +
                                                std::to_string(image_size_.width) + "x" +
                                                std::to_string(image_size_.height) + " image");
    checkFieldOfView(camera_, image_size_, root_ / "cam_K.txt");
    const auto first_mask = mask(0);
    if (!first_mask) throw InputError(maskPath(0), "the first frame needs an object mask: file not found");
    if (cv::countNonZero(*first_mask) == 0) throw InputError(maskPath(0), "the first frame's object mask is empty");
    checkDepthScale(rawDepth(0), *first_mask, settings_.depth_scale, depthPath(0));
  }

  std::size_t size() const { return names_.size(); }
  const std::vector<std::string>& frameNames() const { return names_; }
  const std::filesystem::path& root() const { return root_; }
  const PinholeCamerad& camera() const { return camera_; }
  cv::Size imageSize() const { return image_size_; }

  /// Loads and preprocesses frame i. Throws InputError for an unreadable file, a size mismatch or
  /// a depth image without a single valid reading.
  RgbdFrame frame(std::size_t i) const { return preprocess(read(i)); }

  /// Decodes frame i's files (colour, depth in metres, the mask if there is one), nothing more;
  /// safe to call from another thread (to read ahead), throws as frame() does.
  RawFrame read(std::size_t i) const {
    cv::Mat color = readColor(colorPath(i));
    requireSize(color, colorPath(i));
    return {names_.at(i), std::move(color), rawDepth(i), mask(i).value_or(cv::Mat())};
  }

  /// Preprocesses a frame from read(), only inside `region` (Tracker::regionOfInterest; empty:
  /// the whole image), with the sequence's frame settings.
  RgbdFrame preprocess(RawFrame raw, cv::Rect region = {}) const {
    return makeFrame(std::move(raw), camera_.cast<float>(), settings_.frame, region);
  }

  /// Depth of frame i in metres as stored, before filtering.
  cv::Mat rawDepth(std::size_t i) const {
    const auto path = depthPath(i);
    const cv::Mat depth = readDepth(path, settings_.depth_scale);
    requireSize(depth, path);
    if (cv::countNonZero(depth) == 0) throw InputError(path, "depth image has no valid pixel (all zero)");
    return depth;
  }

  /// The mask of frame i, or nothing when masks/<name>.png does not exist.
  std::optional<cv::Mat> mask(std::size_t i) const {
    const auto path = maskPath(i);
    if (!std::filesystem::exists(path)) return std::nullopt;
    cv::Mat m = readMask(path);
    requireSize(m, path);
    return m;
  }

  /// Frame i's files (the mask's may not exist).
  std::filesystem::path colorPath(std::size_t i) const { return root_ / "rgb" / color_files_.at(i); }
  std::filesystem::path depthPath(std::size_t i) const { return root_ / "depth" / (names_.at(i) + ".png"); }
  std::filesystem::path maskPath(std::size_t i) const { return root_ / "masks" / (names_.at(i) + ".png"); }

  bool hasGroundTruth() const { return std::filesystem::is_directory(root_ / "annotated_poses"); }
  SE3d groundTruthPose(std::size_t i) const { return readPose(root_ / "annotated_poses" / (names_.at(i) + ".txt")); }

  bool hasModel() const { return std::filesystem::is_regular_file(modelPath()); }
  std::vector<Eigen::Vector3f> modelPoints() const { return readPoints(modelPath()); }

 private:
  void requireSize(const cv::Mat& image, const std::filesystem::path& path) const {
    if (image.size() != image_size_)
      throw InputError(path, "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                 " but the colour images are " + std::to_string(image_size_.width) + "x" +
                                 std::to_string(image_size_.height));
  }

  std::filesystem::path modelPath() const { return root_ / "model" / "points.xyz"; }

  std::filesystem::path root_;
  SequenceSettings settings_;
  std::vector<std::string> names_;
  std::vector<std::string> color_files_;
  PinholeCamerad camera_;
  cv::Size image_size_;
};

}  // namespace bundletrack::io
