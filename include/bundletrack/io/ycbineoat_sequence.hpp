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
    checkFieldOfView();
    const auto first_mask = mask(0);
    if (!first_mask) throw InputError(maskPath(0), "the first frame needs an object mask: file not found");
    if (cv::countNonZero(*first_mask) == 0) throw InputError(maskPath(0), "the first frame's object mask is empty");
    checkDepthScale(*first_mask);
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
  /// The commonest mistake with a new dataset is the depth unit: the object's median depth in the
  /// first frame must lie between 5 cm and 20 m, the range of any RGB-D sensor.
  void checkDepthScale(const cv::Mat& first_mask) const {
    const cv::Mat depth = rawDepth(0);
    std::vector<float> values;
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u)
        if (first_mask.at<uchar>(v, u) && depth.at<float>(v, u) > 0.0f) values.push_back(depth.at<float>(v, u));
    const auto path = depthPath(0);
    if (values.empty()) throw InputError(path, "no valid depth under the first frame's object mask");
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
    const double median = values[values.size() / 2], scale = settings_.depth_scale;
    const std::string stated = "median object depth is " + std::to_string(median) + " m with depth scale " +
                               std::to_string(scale) + " m/unit";
    if (median < 0.05)
      throw InputError(path, stated + ": closer than any RGB-D sensor measures; the depth scale is probably too small"
                                      " (images in millimetres need 0.001, in 0.1 mm 0.0001)");
    if (median > 20.0)
      throw InputError(path, stated + ": farther than any RGB-D sensor measures; the depth scale is probably too large"
                                      " (images in millimetres need 0.001, not 1)");
  }

  /// K must fit the images: RGB-D cameras see 40-120 degrees across (Kinect v1 57, RealSense D435
  /// 69-87, Azure Kinect 75-120), so a field of view outside 10-170 degrees, or pixels more than
  /// twice as tall as wide (fx / fy), is a K for another image size or in other units.
  void checkFieldOfView() const {
    const auto view = [](double pixels, double focal) { return degrees(2.0 * std::atan(0.5 * pixels / focal)); };
    const double across = view(image_size_.width, camera_.fx), down = view(image_size_.height, camera_.fy);
    const std::string stated = "fx " + std::to_string(camera_.fx) + " px, fy " + std::to_string(camera_.fy) +
                               " px give a field of view of " + std::to_string(across) + " x " + std::to_string(down) +
                               " degrees for the " + std::to_string(image_size_.width) + "x" +
                               std::to_string(image_size_.height) + " images";
    if (std::min(across, down) < 10.0 || std::max(across, down) > 170.0)
      throw InputError(root_ / "cam_K.txt", stated + "; RGB-D cameras see 40-120 degrees: is K for another image size "
                                                     "or in other units?");
    const double aspect = camera_.fx / camera_.fy;
    if (aspect < 0.5 || aspect > 2.0)
      throw InputError(root_ / "cam_K.txt", stated + ": fx / fy = " + std::to_string(aspect) +
                                                ", pixels far from square: is K mistyped?");
  }

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
