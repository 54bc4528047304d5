#pragma once

#include <algorithm>
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
#include "bundletrack/io/label_images.hpp"
#include "bundletrack/io/point_files.hpp"
#include "bundletrack/io/pose_files.hpp"
#include "bundletrack/io/sequence_layouts.hpp"

namespace bundletrack::io {

struct SequenceSettings {
  /// Metres per unit of the 16-bit depth images; 0: the layout's own (YCBInEOAT 0.001, i.e.
  /// millimetres; TUM RGB-D 1/5000).
  double depth_scale = 0.0;
  Layout layout = Layout::Auto;
  double max_time_difference = 0.02;  ///< seconds between a TUM colour image and its depth (associate.py's default)
  FrameSettings frame;
};

/// A sequence folder, its frames listed by its layout (io/sequence_layouts.hpp: YCBInEOAT or TUM
/// RGB-D), and beside them:
///   masks/<name>.png     object mask     (the first frame's is required, later ones optional)
///   cam_K.txt            3x3 intrinsics  annotated_poses/<name>.txt  4x4 T_cam_obj (optional)
///   model/points.xyz     object points in the object frame (optional)
/// where <name> is a frame's colour image's file stem. Several objects: masks/ holds a folder per
/// object instead (masks/<object>/<name>.png; an object starts at its first non-empty mask, and
/// the first frame needs none), and so do annotated_poses/<object>/ and model/<object>/. Or a
/// label image per frame, labels/<name>.png (8 or 16 bits, one channel: each pixel the label of
/// the object it shows, 0 none), with labels/objects.txt naming the labels (readLabelNames).
class RgbdSequence {
 public:
  explicit RgbdSequence(std::filesystem::path root, SequenceSettings settings = {})
      : root_(std::move(root)), settings_(std::move(settings)) {
    if (!std::filesystem::is_directory(root_)) throw InputError(root_, "sequence directory not found");
    if (!(settings_.depth_scale >= 0.0)) throw InputError(root_, "depth scale must be positive (or 0: the layout's)");
    frames_ = frameFiles(root_, settings_.layout, settings_.max_time_difference);
    depth_scale_ = settings_.depth_scale > 0.0 ? settings_.depth_scale : frames_.depth_unit;
    if (const auto folder = depthPath(0).parent_path(); !depthPath(0).empty() && !std::filesystem::is_directory(folder))
      throw InputError(folder, "directory not found");
    camera_ = readIntrinsics(root_ / "cam_K.txt");

    const cv::Mat first_color = readColor(colorPath(0));
    image_size_ = first_color.size();
    if (camera_.cx < 0.0 || camera_.cx >= image_size_.width || camera_.cy < 0.0 || camera_.cy >= image_size_.height)
      throw InputError(root_ / "cam_K.txt", "principal point (" + std::to_string(camera_.cx) + ", " +
                                                std::to_string(camera_.cy) + ") lies outside the " +
                                                std::to_string(image_size_.width) + "x" +
                                                std::to_string(image_size_.height) + " image");
    checkFieldOfView(camera_, image_size_, root_ / "cam_K.txt");
    objects_ = listObjects();
    if (!objects_.empty()) {
      // The depth unit is judged under the objects visible in the first frame, else over the whole frame.
      cv::Mat visible = cv::Mat::zeros(image_size_, CV_8UC1);
      for (const std::string& object : objects_)
        if (const auto m = mask(0, object)) visible |= *m;
      if (cv::countNonZero(visible) == 0) visible.setTo(255);
      warnDepthScale(checkDepthScale(rawDepth(0), visible, depth_scale_, depthPath(0), settings_.frame.sensor.max_range));
      return;
    }
    const auto first_mask = mask(0);
    if (!first_mask) throw InputError(maskPath(0), "the first frame needs an object mask: file not found");
    if (cv::countNonZero(*first_mask) == 0) throw InputError(maskPath(0), "the first frame's object mask is empty");
    warnDepthScale(checkDepthScale(rawDepth(0), *first_mask, depth_scale_, depthPath(0), settings_.frame.sensor.max_range));
  }

  /// What the reader found doubtful but not wrong (checkDepthScale's caution), for the user to see.
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// The objects of a sequence with a folder of masks per object (in name order) or with label
  /// images (in the order of labels/objects.txt); empty for a sequence of one object
  /// (masks/<name>.png), whose functions below take the object "".
  const std::vector<std::string>& objects() const { return objects_; }

  /// Where the objects are listed: masks/, or labels/objects.txt.
  std::filesystem::path objectList() const { return labels_.empty() ? root_ / "masks" : labelNamesPath(); }

  std::size_t size() const { return frames_.names.size(); }
  const std::vector<std::string>& frameNames() const { return frames_.names; }
  double depthScale() const { return depth_scale_; }  ///< metres per unit, as used
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
    return {frames_.names.at(i), std::move(color), rawDepth(i), mask(i).value_or(cv::Mat())};
  }

  /// Preprocesses a frame from read(), only inside `region` (Tracker::regionOfInterest; empty:
  /// the whole image), with the sequence's frame settings.
  RgbdFrame preprocess(RawFrame raw, cv::Rect region = {}) const {
    return makeFrame(std::move(raw), camera_.cast<float>(), settings_.frame, region);
  }

  /// Depth of frame i in metres as stored, before filtering.
  cv::Mat rawDepth(std::size_t i) const {
    const auto path = depthPath(i);
    if (path.empty()) throw InputError(colorPath(i), frames_.missing_depth.at(i));
    const cv::Mat depth = readDepth(path, depth_scale_);
    requireSize(depth, path);
    if (cv::countNonZero(depth) == 0) throw InputError(path, "depth image has no valid pixel (all zero)");
    return depth;
  }

  /// The mask of frame i (of `object`), or nothing when its file does not exist.
  std::optional<cv::Mat> mask(std::size_t i, const std::string& object = {}) const {
    const auto path = maskPath(i, object);
    if ((!labels_.empty() && object.empty()) || !std::filesystem::exists(path)) return std::nullopt;
    if (!labels_.empty()) return labelMask(readLabelImage(path), labelOf(object));
    cv::Mat m = readMask(path);
    requireSize(m, path);
    return m;
  }

  /// The masks of frame i of every object of objects(), in that order (a label image is read once).
  std::vector<std::optional<cv::Mat>> masks(std::size_t i) const {
    std::vector<std::optional<cv::Mat>> all;
    if (labels_.empty()) {
      for (const std::string& object : objects_) all.push_back(mask(i, object));
      return all;
    }
    const auto path = maskPath(i);
    const std::optional<cv::Mat> image = std::filesystem::exists(path) ? std::optional(readLabelImage(path)) : std::nullopt;
    for (const int label : labels_) all.push_back(image ? std::optional(labelMask(*image, label)) : std::nullopt);
    return all;
  }

  /// Frame i's files (the mask's may not exist).
  std::filesystem::path colorPath(std::size_t i) const { return frames_.color.at(i); }
  std::filesystem::path depthPath(std::size_t i) const { return frames_.depth.at(i); }  ///< empty: none
  std::filesystem::path maskPath(std::size_t i, const std::string& object = {}) const {
    if (!labels_.empty()) return root_ / "labels" / (frames_.names.at(i) + ".png");
    return folder("masks", object) / (frames_.names.at(i) + ".png");
  }

  bool hasGroundTruth(const std::string& object = {}) const { return std::filesystem::is_directory(folder("annotated_poses", object)); }
  SE3d groundTruthPose(std::size_t i, const std::string& object = {}) const {
    return readPose(folder("annotated_poses", object) / (frames_.names.at(i) + ".txt"));
  }

  bool hasModel(const std::string& object = {}) const { return std::filesystem::is_regular_file(modelPath(object)); }
  std::vector<Eigen::Vector3f> modelPoints(const std::string& object = {}) const { return readPoints(modelPath(object)); }

 private:
  void warnDepthScale(std::string caution) {
    if (!caution.empty()) warnings_.push_back(std::move(caution));
  }

  void requireSize(const cv::Mat& image, const std::filesystem::path& path) const {
    if (image.size() != image_size_)
      throw InputError(path, "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                 " but the colour images are " + std::to_string(image_size_.width) + "x" +
                                 std::to_string(image_size_.height));
  }

  /// root/<kind>, or its subfolder of `object`.
  std::filesystem::path folder(const char* kind, const std::string& object) const {
    return object.empty() ? root_ / kind : root_ / kind / object;
  }
  std::filesystem::path modelPath(const std::string& object) const { return folder("model", object) / "points.xyz"; }

  std::filesystem::path labelNamesPath() const { return root_ / "labels" / "objects.txt"; }

  /// The objects' names: the folders of masks/ when the first frame has no mask of its own
  /// (masks/<name>.png), or those of labels/objects.txt (their labels into labels_). A sequence
  /// with both is refused: which one would be meant?
  std::vector<std::string> listObjects() {
    std::vector<std::string> names;
    std::error_code error;
    if (!std::filesystem::exists(maskPath(0)) && std::filesystem::is_directory(root_ / "masks", error))
      for (const auto& entry : std::filesystem::directory_iterator(root_ / "masks"))
        if (entry.is_directory()) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    if (!std::filesystem::exists(root_ / "labels")) return names;
    if (std::filesystem::exists(maskPath(0)) || !names.empty())
      throw InputError(root_ / "labels", "the sequence has both label images and masks/: keep one of them");
    for (const auto& [label, name] : readLabelNames(labelNamesPath())) {
      labels_.push_back(label);
      names.push_back(name);
    }
    return names;
  }

  int labelOf(const std::string& object) const {
    const auto at = std::find(objects_.begin(), objects_.end(), object);
    if (at == objects_.end()) throw InputError(labelNamesPath(), "no object '" + object + "'");
    return labels_[std::size_t(at - objects_.begin())];
  }

  cv::Mat readLabelImage(const std::filesystem::path& path) const {
    cv::Mat labels = labelsFromImage(readImage(path, cv::IMREAD_UNCHANGED), path);
    requireSize(labels, path);
    return labels;
  }

  std::filesystem::path root_;
  SequenceSettings settings_;
  FrameFiles frames_;
  std::vector<std::string> objects_;
  std::vector<int> labels_;  ///< of each object, in a sequence with label images (else empty)
  std::vector<std::string> warnings_;
  double depth_scale_ = 0.001;
  PinholeCamerad camera_;
  cv::Size image_size_;
};

}  // namespace bundletrack::io
