// The Python module `bundletrack`: the tracker a configuration describes (makeTracker), fed
// numpy arrays as OpenCV and pyrealsense2 give them; the YCBInEOAT sequence reader; the metrics.
// Arrays are used in place where their layout allows (C-contiguous, the right dtype); wrong
// dtypes raise TypeError, wrong shapes and values ValueError with the library's InputError text.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bundletrack/config/config_file.hpp"
#include "bundletrack/eval/pose_metrics.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/io/model_file.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/tracking/multi_object_tracker.hpp"

namespace py = pybind11;
namespace bt = bundletrack;

namespace {

using Matrix4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

std::string shapeText(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d) text += (d ? ", " : "") + std::to_string(array.shape(d));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

std::string dtypeText(const py::array& array) { return py::str(array.dtype()).cast<std::string>(); }

/// An array argument: a numpy array (anything else is a TypeError naming the argument).
py::array arrayArgument(const py::handle& value, const char* name) {
  if (!py::isinstance<py::array>(value))
    throw py::type_error(std::string(name) + ": expected a numpy array, got " +
                         py::str(py::type::of(value).attr("__name__")).cast<std::string>());
  return py::reinterpret_borrow<py::array>(value);
}

/// A cv::Mat over an array's data, and the array that owns the data (C-contiguous: the caller's
/// own array when it already is, else a contiguous copy).
struct MatView {
  py::array owner;
  cv::Mat mat;
};

MatView matView(const py::array& array, int type) {
  py::array contiguous = py::array::ensure(array, py::array::c_style);
  cv::Mat mat(int(contiguous.shape(0)), int(contiguous.shape(1)), type, const_cast<void*>(contiguous.data()));
  return {std::move(contiguous), mat};
}

/// A copy of an image as a numpy array (HxW or HxWxC).
template <typename T>
py::array_t<T> arrayOf(const cv::Mat& image) {
  std::vector<py::ssize_t> shape{image.rows, image.cols};
  if (image.channels() > 1) shape.push_back(image.channels());
  py::array_t<T> out(shape);
  cv::Mat target(image.rows, image.cols, image.type(), out.mutable_data());
  image.copyTo(target);
  return out;
}

/// 8-bit BGR colour, HxWx3 uint8 (as OpenCV reads it; pyrealsense2's bgr8).
MatView colorArgument(const py::handle& value) {
  const py::array array = arrayArgument(value, "rgb");
  if (!array.dtype().is(py::dtype::of<std::uint8_t>()))
    throw py::type_error("rgb: expected dtype uint8 (8-bit BGR), got " + dtypeText(array));
  if (array.ndim() != 3 || array.shape(2) != 3)
    throw bt::InputError("rgb", "expected an HxWx3 BGR image, got shape " + shapeText(array));
  return matView(array, CV_8UC3);
}

/// Depth in metres (CV_32FC1): uint16 times depth.scale (a file's or pyrealsense2's z16 units),
/// or float32 metres (used in place; NaN and infinity mean no reading, as 0 does).
cv::Mat depthArgument(const py::handle& value, double scale, cv::Size size, py::array& keep_alive) {
  const py::array array = arrayArgument(value, "depth");
  const bool units = array.dtype().is(py::dtype::of<std::uint16_t>());
  if (!units && !array.dtype().is(py::dtype::of<float>()))
    throw py::type_error("depth: expected dtype uint16 (times depth.scale) or float32 (metres), got " + dtypeText(array));
  if (array.ndim() != 2 || array.shape(0) != size.height || array.shape(1) != size.width)
    throw bt::InputError("depth", "expected an HxW array of the colour image's size (" + std::to_string(size.height) +
                                      ", " + std::to_string(size.width) + "), got shape " + shapeText(array));
  MatView view = matView(array, units ? CV_16UC1 : CV_32FC1);
  if (units) return bt::io::depthFromImage(view.mat, scale, "depth");
  if (!cv::checkRange(view.mat)) {
    cv::Mat finite = view.mat.clone();
    finite.setTo(0.0f, finite != finite);  // NaN
    finite.setTo(0.0f, cv::abs(finite) == std::numeric_limits<float>::infinity());
    return finite;
  }
  keep_alive = std::move(view.owner);
  return view.mat;
}

/// The object mask (CV_8UC1, 0 or 255): bool, or uint8 non-zero on the object, HxW.
cv::Mat maskArgument(const py::handle& value, cv::Size size) {
  const py::array array = arrayArgument(value, "mask");
  const bool boolean = array.dtype().is(py::dtype::of<bool>());
  if (!boolean && !array.dtype().is(py::dtype::of<std::uint8_t>()))
    throw py::type_error("mask: expected dtype bool or uint8 (non-zero on the object), got " + dtypeText(array));
  if (array.ndim() != 2 || array.shape(0) != size.height || array.shape(1) != size.width)
    throw bt::InputError("mask", "expected an HxW array of the colour image's size (" + std::to_string(size.height) +
                                     ", " + std::to_string(size.width) + "), got shape " + shapeText(array));
  return bt::io::maskFromImage(matView(array, CV_8UC1).mat);
}

/// The numbers of a rows x cols matrix argument (anything numpy turns into one), row by row.
std::vector<double> matrixArgument(const py::handle& value, int rows, int cols, const char* name) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || py::isinstance<py::str>(value))
    throw py::type_error(std::string(name) + ": expected a " + std::to_string(rows) + "x" + std::to_string(cols) +
                         " matrix of numbers");
  if (array.ndim() != 2 || array.shape(0) != rows || array.shape(1) != cols)
    throw bt::InputError(name, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, got shape " +
                                   shapeText(array));
  return {array.data(), array.data() + array.size()};
}

bt::SE3d poseArgument(const py::handle& value, const char* name) {
  return bt::io::poseFromNumbers(matrixArgument(value, 4, 4, name), name);
}

Matrix4 matrixOf(const bt::SE3d& pose) { return pose.matrix(); }

/// A setting's value as YAML text: a number, or a quoted name.
std::string yamlValue(const py::handle& value, const std::string& key) {
  const py::module_ numbers = py::module_::import("numbers");
  if (py::isinstance<py::bool_>(value)) throw py::type_error("config: " + key + " is a number or a name, not a bool");
  if (py::isinstance(value, numbers.attr("Integral"))) return py::str(py::int_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
  if (py::isinstance(value, numbers.attr("Real"))) {
    const double number = py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
    if (std::isinf(number)) return number > 0 ? ".inf" : "-.inf";
    if (std::isnan(number)) throw bt::InputError("config", key + " is NaN");
    std::ostringstream text;
    text.precision(17);
    text << number;
    return text.str();
  }
  if (py::isinstance<py::str>(value)) {
    std::string quoted = "\"";
    for (const char c : value.cast<std::string>()) quoted += c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c);
    return quoted + "\"";
  }
  throw py::type_error("config: " + key + " must be a number or a name, got " +
                       py::str(py::type::of(value).attr("__name__")).cast<std::string>());
}

/// A configuration: None or {} (the defaults), a dict of sections of settings as in the YAML
/// file ({"features": {"type": "orb"}}), or the path of a YAML file. The dict goes through the
/// YAML reader, so it is checked as a file is (unknown keys, ranges, choices).
bt::Config configArgument(const py::object& config) {
  if (config.is_none()) return bt::Config();
  if (py::isinstance<py::str>(config) || py::isinstance(config, py::module_::import("os").attr("PathLike")))
    return bt::loadConfig(py::str(py::module_::import("os").attr("fspath")(config)).cast<std::string>());
  if (!py::isinstance<py::dict>(config))
    throw py::type_error("config: expected a dict of sections, a YAML file's path or None");
  std::string yaml;
  for (const auto& [section, settings] : config.cast<py::dict>()) {
    if (!py::isinstance<py::str>(section)) throw py::type_error("config: section names must be strings");
    const std::string name = section.cast<std::string>();
    if (!py::isinstance<py::dict>(settings))
      throw py::type_error("config: section '" + name + "' must be a dict of key: value (e.g. {'features': {'type': 'orb'}})");
    yaml += name + ":\n";
    for (const auto& [key, value] : settings.cast<py::dict>()) {
      if (!py::isinstance<py::str>(key)) throw py::type_error("config: keys of section '" + name + "' must be strings");
      yaml += "  " + key.cast<std::string>() + ": " + yamlValue(value, name + "." + key.cast<std::string>()) + "\n";
    }
  }
  return bt::parseConfig(yaml, "config");
}

/// One frame's answer.
struct Result {
  Matrix4 pose;
  std::string status;
  int keypoints, matches, inliers;
  bool by_surface;
  int followed;
  py::object stability;
  py::dict timings;
  py::object mask;
};

Result resultOf(const bt::TrackResult& r) {
  py::dict timings;
  const auto& t = r.timings;
  for (const auto& [name, ms] : {std::pair{"mask", t.mask}, {"features", t.features}, {"matching", t.matching},
                                 {"ransac", t.ransac}, {"graph", t.graph}, {"solve", t.solve}, {"total", t.total}})
    timings[name] = ms;
  const py::object stability = r.stability ? py::object(py::float_(*r.stability)) : py::object(py::none());
  const py::object mask = r.mask.empty() ? py::object(py::none()) : py::object(arrayOf<std::uint8_t>(r.mask));
  return {matrixOf(r.T_cam_obj), std::string(bt::statusName(r.status)), r.keypoints, r.matches, r.inliers, r.surface_only,
          r.followed, stability, timings, mask};
}

/// Shows a caution of the readers (e.g. checkDepthScale's) as a Python UserWarning.
void warn(const std::string& caution) {
  if (!caution.empty() && PyErr_WarnEx(PyExc_UserWarning, caution.c_str(), 1) != 0) throw py::error_already_set();
}

/// The object model's arrays: points and normals (Nx3 float32, object frame, metres) and colours
/// (Nx3 uint8 BGR).
py::dict modelArrays(const std::vector<bt::ModelPoint>& model) {
  py::array_t<float> points({py::ssize_t(model.size()), py::ssize_t(3)}), normals({py::ssize_t(model.size()), py::ssize_t(3)});
  py::array_t<std::uint8_t> colors({py::ssize_t(model.size()), py::ssize_t(3)});
  auto p = points.mutable_unchecked<2>();
  auto n = normals.mutable_unchecked<2>();
  auto c = colors.mutable_unchecked<2>();
  for (py::ssize_t k = 0; k < py::ssize_t(model.size()); ++k)
    for (py::ssize_t d = 0; d < 3; ++d) {
      p(k, d) = model[std::size_t(k)].position[d];
      n(k, d) = model[std::size_t(k)].normal[d];
      c(k, d) = model[std::size_t(k)].color[int(d)];
    }
  py::dict out;
  out["points"] = points, out["normals"] = normals, out["colors"] = colors;
  return out;
}

/// A later frame's colour image must have the first frame's size.
void requireFirstSize(const cv::Mat& color, cv::Size first) {
  if (color.size() != first)
    throw bt::InputError("rgb", "image is " + std::to_string(color.cols) + "x" + std::to_string(color.rows) +
                                    " but the first frame's is " + std::to_string(first.width) + "x" +
                                    std::to_string(first.height));
}

/// Metres per unit of uint16 depth arrays: depth.scale, or millimetres when it is 0 (the layout's).
double depthScaleOf(const bt::Config& config) { return config.sequence.depth_scale > 0.0 ? config.sequence.depth_scale : 0.001; }

/// The tracker of a configuration, made at initialize() from the first frame's intrinsics.
class PyTracker {
 public:
  explicit PyTracker(const py::object& config) : config_(configArgument(config)) {}

  Result initialize(const py::handle& rgb, const py::handle& depth, const py::handle& mask, const py::handle& K,
                    const py::handle& pose) {
    MatView color = colorArgument(rgb);
    const cv::Size size = color.mat.size();
    const bt::PinholeCamerad camera = bt::io::intrinsicsFromNumbers(matrixArgument(K, 3, 3, "K"), "K");
    bt::io::checkFieldOfView(camera, size, "K");
    py::array depth_owner;
    const cv::Mat metres = depthArgument(depth, depthScaleOf(config_), size, depth_owner);
    if (mask.is_none()) throw bt::InputError("mask", "the first frame needs the object's mask");
    const cv::Mat object = maskArgument(mask, size);
    if (cv::countNonZero(object) == 0) throw bt::InputError("mask", "the first frame's object mask is empty");
    warn(bt::io::checkDepthScale(metres, object, depthScaleOf(config_), "depth", config_.sequence.frame.sensor.max_range));
    const bt::SE3d T_cam_obj = pose.is_none() ? bt::SE3d() : poseArgument(pose, "pose");
    std::unique_ptr<bt::AnyTracker> tracker = bt::makeTracker(config_, camera.cast<float>());
    bt::TrackResult result;
    {
      py::gil_scoped_release unlocked;
      const bt::RgbdFrame frame = bt::makeFrame("0", color.mat, metres, object, camera.cast<float>(), config_.sequence.frame);
      result = tracker->initialize(frame, T_cam_obj);
    }
    tracker_ = std::move(tracker);
    camera_ = camera;
    size_ = size;
    frames_ = 1;
    return resultOf(result);
  }

  Result track(const py::handle& rgb, const py::handle& depth, const py::handle& mask) {
    if (!tracker_) throw std::runtime_error("track() called before initialize()");
    MatView color = colorArgument(rgb);
    requireFirstSize(color.mat, size_);
    py::array depth_owner;
    const cv::Mat metres = depthArgument(depth, depthScaleOf(config_), size_, depth_owner);
    const bool propagated = config_.masks == "propagated";
    if (propagated && !mask.is_none())
      throw bt::InputError("mask", "masks.source is 'propagated': the tracker follows the first mask, pass none");
    if (!propagated && mask.is_none())
      throw bt::InputError("mask", "masks.source is 'given': every frame needs the object's mask (or configure "
                                   "{'masks': {'source': 'propagated'}})");
    const cv::Mat object = propagated ? cv::Mat() : maskArgument(mask, size_);
    bt::TrackResult result;
    {
      py::gil_scoped_release unlocked;
      const cv::Rect region = tracker_->regionOfInterest(size_, object);
      const bt::RgbdFrame frame = bt::makeFrame(std::to_string(frames_), color.mat, metres, object, camera_.cast<float>(),
                                                config_.sequence.frame, region);
      result = tracker_->track(frame);
    }
    ++frames_;
    return resultOf(result);
  }

  /// The object's model fused from the keyframes (modelArrays).
  py::dict objectModel() const {
    return modelArrays(tracker_ ? tracker_->objectModel() : std::vector<bt::ModelPoint>());
  }

  void writeModel(const std::filesystem::path& path) const {
    if (!tracker_) throw std::runtime_error("write_model() called before initialize()");
    bt::io::writeModelPly(path, tracker_->objectModel());
  }

  int frames() const { return frames_; }
  std::size_t keyframes() const { return tracker_ ? tracker_->keyframeCount() : 0; }
  std::string configYaml() const { return bt::printConfig(config_); }

 private:
  bt::Config config_;
  std::unique_ptr<bt::AnyTracker> tracker_;
  bt::PinholeCamerad camera_{};
  cv::Size size_;
  int frames_ = 0;
};

/// Several objects in one camera (MultiObjectTracker): each frame is read and preprocessed once,
/// over the union of the regions the objects' trackers ask for, and each object has a tracker of
/// its own that starts with the first frame bringing a non-empty mask of it.
class PyMultiTracker {
 public:
  PyMultiTracker(std::vector<std::string> objects, const py::handle& K, const py::object& config)
      : config_(configArgument(config)), objects_(std::move(objects)),
        camera_(bt::io::intrinsicsFromNumbers(matrixArgument(K, 3, 3, "K"), "K")) {
    if (objects_.empty()) throw bt::InputError("objects", "name at least one object");
    for (std::size_t k = 0; k < objects_.size(); ++k)
      if (std::find(objects_.begin(), objects_.begin() + std::ptrdiff_t(k), objects_[k]) != objects_.begin() + std::ptrdiff_t(k))
        throw bt::InputError("objects", "'" + objects_[k] + "' is named twice");
    tracker_.emplace(objects_.size(), [&] { return bt::makeTracker(config_, camera_.cast<float>()); });
  }

  /// One frame for every object: masks maps names to HxW masks (a name left out or None: that
  /// object sits the frame out, or, with masks.source 'propagated' once it has started, follows
  /// its own masks); poses maps names to the 4x4 T_cam_obj an object starts at (identity).
  py::dict track(const py::handle& rgb, const py::handle& depth, const py::handle& masks, const py::handle& poses) {
    MatView color = colorArgument(rgb);
    if (frames_ == 0) {
      bt::io::checkFieldOfView(camera_, color.mat.size(), "K");
      size_ = color.mat.size();
    }
    requireFirstSize(color.mat, size_);
    py::array depth_owner;
    const cv::Mat metres = depthArgument(depth, depthScaleOf(config_), size_, depth_owner);
    const py::dict given = namedArgument(masks, "masks");
    const py::dict starts = namedArgument(poses, "poses");
    const bool propagated = config_.masks == "propagated";
    bt::MultiObjectTracker::ObjectMasks object_masks(objects_.size());
    std::vector<bt::SE3d> start_poses(objects_.size());
    cv::Mat seen = cv::Mat::zeros(size_, CV_8UC1);
    for (std::size_t k = 0; k < objects_.size(); ++k) {
      const std::string& name = objects_[k];
      const std::string mask_name = "masks['" + name + "']", pose_name = "poses['" + name + "']";
      const py::object mask = given.contains(name) ? py::object(given[name.c_str()]) : py::object(py::none());
      if (propagated && tracker_->started(k)) {
        if (!mask.is_none())
          throw bt::InputError(mask_name, "masks.source is 'propagated': a started object follows its own masks, pass none");
        object_masks[k] = cv::Mat();
      } else if (!mask.is_none()) {
        object_masks[k] = maskArgument(mask, size_);
        seen |= *object_masks[k];
      }
      if (starts.contains(name)) start_poses[k] = poseArgument(starts[name.c_str()], pose_name.c_str());
    }
    if (frames_ == 0) {
      if (cv::countNonZero(seen) == 0) seen.setTo(255);
      warn(bt::io::checkDepthScale(metres, seen, depthScaleOf(config_), "depth", config_.sequence.frame.sensor.max_range));
    }
    std::vector<std::optional<bt::TrackResult>> results;
    {
      py::gil_scoped_release unlocked;
      const cv::Rect region = tracker_->regionOfInterest(size_, object_masks);
      const bt::RgbdFrame frame = bt::makeFrame(std::to_string(frames_), color.mat, metres, cv::Mat(), camera_.cast<float>(),
                                                config_.sequence.frame, region);
      results = tracker_->track(frame, object_masks, start_poses);
    }
    ++frames_;
    py::dict out;
    for (std::size_t k = 0; k < objects_.size(); ++k)
      out[objects_[k].c_str()] = results[k] ? py::cast(resultOf(*results[k])) : py::object(py::none());
    return out;
  }

  py::dict objectModel(const std::string& name) const { return modelArrays(tracker_->tracker(indexOf(name)).objectModel()); }
  const std::vector<std::string>& objects() const { return objects_; }
  int frames() const { return frames_; }
  py::dict started() const {
    py::dict out;
    for (std::size_t k = 0; k < objects_.size(); ++k) out[objects_[k].c_str()] = tracker_->started(k);
    return out;
  }

 private:
  std::size_t indexOf(const std::string& name) const {
    const auto at = std::find(objects_.begin(), objects_.end(), name);
    if (at == objects_.end()) throw bt::InputError("object", "no object '" + name + "' (objects: " + objectList() + ")");
    return std::size_t(at - objects_.begin());
  }

  std::string objectList() const {
    std::string list;
    for (const std::string& name : objects_) list += (list.empty() ? "" : ", ") + name;
    return list;
  }

  /// A dict keyed by the tracker's object names (None: empty).
  py::dict namedArgument(const py::handle& value, const char* what) const {
    if (value.is_none()) return py::dict();
    if (!py::isinstance<py::dict>(value))
      throw py::type_error(std::string(what) + ": expected a dict from object names to arrays, or None");
    const py::dict named = value.cast<py::dict>();
    for (const auto& [key, item] : named) {
      if (!py::isinstance<py::str>(key)) throw py::type_error(std::string(what) + ": keys must be object names (str)");
      const std::string name = key.cast<std::string>();
      if (std::find(objects_.begin(), objects_.end(), name) == objects_.end())
        throw bt::InputError(what, "no object '" + name + "' (objects: " + objectList() + ")");
    }
    return named;
  }

  bt::Config config_;
  std::vector<std::string> objects_;
  bt::PinholeCamerad camera_;
  std::optional<bt::MultiObjectTracker> tracker_;
  cv::Size size_;
  int frames_ = 0;
};


/// A sequence folder (README: rgb/, depth/ or rgb.txt, depth.txt; masks/ or labels/; cam_K.txt,
/// annotated_poses/, model/).
class PySequence {
 public:
  PySequence(const std::filesystem::path& path, const py::object& config)
      : sequence_(path, configArgument(config).sequence) {
    for (const std::string& caution : sequence_.warnings()) warn(caution);
  }

  std::size_t size() const { return sequence_.size(); }
  const std::vector<std::string>& names() const { return sequence_.frameNames(); }
  Eigen::Matrix3d intrinsics() const {
    const auto& c = sequence_.camera();
    Eigen::Matrix3d K;
    K << c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0;
    return K;
  }

  /// Frame i: (rgb HxWx3 uint8 BGR, depth HxW float32 metres, mask HxW uint8 or None).
  py::tuple read(std::size_t i) const {
    bt::RawFrame raw = sequence_.read(index(i));
    return py::make_tuple(arrayOf<std::uint8_t>(raw.color), arrayOf<float>(raw.depth),
                          raw.mask.empty() ? py::object(py::none()) : py::object(arrayOf<std::uint8_t>(raw.mask)));
  }

  /// Frame i's masks of every object (dict: name -> HxW uint8 or None), for several objects.
  py::dict masks(std::size_t i) const {
    if (sequence_.objects().empty())
      throw bt::InputError(sequence_.root() / "masks", "a sequence of one object (masks/<frame>.png): use read()");
    const std::vector<std::optional<cv::Mat>> all = sequence_.masks(index(i));
    py::dict out;
    for (std::size_t k = 0; k < all.size(); ++k)
      out[sequence_.objects()[k].c_str()] = all[k] ? py::object(arrayOf<std::uint8_t>(*all[k])) : py::object(py::none());
    return out;
  }

  const std::vector<std::string>& objects() const { return sequence_.objects(); }
  bool hasGroundTruth() const { return sequence_.hasGroundTruth(); }
  Matrix4 groundTruth(std::size_t i, const std::string& object) const {
    return matrixOf(sequence_.groundTruthPose(index(i), object));
  }
  bool hasModel() const { return sequence_.hasModel(); }
  Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> modelPoints(const std::string& object) const {
    const std::vector<Eigen::Vector3f> points = sequence_.modelPoints(object);
    Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> out(points.size(), 3);
    for (std::size_t k = 0; k < points.size(); ++k) out.row(Eigen::Index(k)) = points[k].transpose();
    return out;
  }

 private:
  std::size_t index(std::size_t i) const {
    if (i >= sequence_.size())
      throw py::index_error("frame " + std::to_string(i) + " of a sequence of " + std::to_string(sequence_.size()));
    return i;
  }

  bt::io::RgbdSequence sequence_;
};

std::vector<Eigen::Vector3f> pointsArgument(const py::handle& value) {
  const py::array_t<float, py::array::c_style | py::array::forcecast> array =
      py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 2 || array.shape(1) != 3)
    throw bt::InputError("model", "expected an Nx3 array of object points (metres)");
  if (array.shape(0) == 0) throw bt::InputError("model", "no points");
  std::vector<Eigen::Vector3f> points(std::size_t(array.shape(0)));
  for (std::size_t k = 0; k < points.size(); ++k) {
    points[k] = Eigen::Vector3f(array.at(k, 0), array.at(k, 1), array.at(k, 2));
    if (!points[k].allFinite()) throw bt::InputError("model", "point " + std::to_string(k) + " is not finite");
  }
  return points;
}

py::dict score(const py::handle& model, const py::sequence& truth, const py::sequence& estimates) {
  if (truth.size() != estimates.size())
    throw bt::InputError("estimates", std::to_string(estimates.size()) + " poses for " + std::to_string(truth.size()) +
                                          " true ones");
  std::vector<bt::SE3d> true_poses;
  std::vector<std::optional<bt::SE3d>> estimated;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::string truth_name = "truth[" + std::to_string(i) + ']', estimate_name = "estimates[" + std::to_string(i) + ']';
    true_poses.push_back(poseArgument(truth[i], truth_name.c_str()));
    estimated.push_back(estimates[i].is_none() ? std::nullopt : std::optional(poseArgument(estimates[i], estimate_name.c_str())));
  }
  const bt::SequenceScore s = bt::scoreSequence(pointsArgument(model), true_poses, estimated);
  py::dict out;
  out["add_auc"] = s.add_auc, out["adds_auc"] = s.adds_auc, out["deg5cm5"] = s.deg5cm5, out["iou25"] = s.iou25;
  out["rotation_error_deg"] = s.rotation_error_deg, out["translation_error_cm"] = s.translation_error_cm;
  out["final_add_cm"] = s.final_add_cm, out["frames"] = s.frames, out["missing"] = s.missing;
  return out;
}

}  // namespace

PYBIND11_MODULE(bundletrack, m) {
  m.doc() = "BundleTrack: causal 6-DoF tracking of novel objects in RGB-D video (poses are 4x4 T_cam_obj, metres)";
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const bt::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<Result>(m, "Result", "What the tracker says of one frame")
      .def_readonly("pose", &Result::pose, "4x4 T_cam_obj (object to camera, metres)")
      .def_readonly("status", &Result::status, "'tracked', 'coarse' (the coarse pose stands) or 'lost'")
      .def_property_readonly("tracked", [](const Result& r) { return r.status == "tracked"; })
      .def_readonly("keypoints", &Result::keypoints, "keypoints detected on this frame")
      .def_readonly("matches", &Result::matches, "matches with the last good frame")
      .def_readonly("inliers", &Result::inliers, "RANSAC inliers among them")
      .def_readonly("by_surface", &Result::by_surface, "tracked by the dense term alone (keypoints on demand)")
      .def_readonly("followed", &Result::followed, "keypoints followed from the last frame by optical flow (keypoints on demand; 0: none)")
      .def_readonly("stability", &Result::stability,
                    "how evenly the data hold the pose, up to 1; ~0 where one direction is held far less than the "
                    "strongest (a ratio, not an uncertainty); None without the graph's pose")
      .def_readonly("timings", &Result::timings, "milliseconds per stage: mask, features, matching, ransac, graph, solve, total")
      .def_readonly("mask", &Result::mask, "HxW uint8 mask the frame was tracked with (0 / 255), or None")
      .def("__repr__", [](const Result& r) {
        std::ostringstream text;
        text << "<bundletrack.Result " << r.status << ", " << r.inliers << "/" << r.matches << " inliers, "
             << r.timings["total"].cast<double>() << " ms>";
        return text.str();
      });

  py::class_<PyTracker>(m, "Tracker",
                        "Tracker(config=None): the tracker a configuration describes; config is None or {} for "
                        "the defaults, a dict of sections as in the YAML file ({'features': {'type': 'orb'}}) or "
                        "a YAML file's path (keys: bundletrack_track --print-config)")
      .def(py::init<const py::object&>(), py::arg("config") = py::none())
      .def("initialize", &PyTracker::initialize, py::arg("rgb"), py::arg("depth"), py::arg("mask"), py::arg("K"),
           py::arg("pose") = py::none(),
           "Starts the track on the first frame: rgb HxWx3 uint8 BGR, depth HxW uint16 (times depth.scale) or "
           "float32 metres, mask HxW bool / uint8, K 3x3 intrinsics, pose 4x4 T_cam_obj (None: identity)")
      .def("track", &PyTracker::track, py::arg("rgb"), py::arg("depth"), py::arg("mask") = py::none(),
           "Tracks the next frame (its mask with masks.source 'given', the default; none with 'propagated')")
      .def("object_model", &PyTracker::objectModel,
           "the object's model fused from the keyframes: {'points', 'normals'} Nx3 float32 (object frame, metres), "
           "{'colors'} Nx3 uint8 BGR")
      .def("write_model", &PyTracker::writeModel, py::arg("path"), "writes the object model as a PLY point cloud")
      .def_property_readonly("frames", &PyTracker::frames, "frames seen so far")
      .def_property_readonly("keyframes", &PyTracker::keyframes, "keyframes in memory")
      .def_property_readonly("config_yaml", &PyTracker::configYaml, "the effective configuration as YAML");

  py::class_<PySequence>(m, "Sequence", "Sequence(path, config=None): a sequence folder, YCBInEOAT or TUM RGB-D layout (README)")
      .def(py::init<const std::filesystem::path&, const py::object&>(), py::arg("path"), py::arg("config") = py::none())
      .def("__len__", &PySequence::size)
      .def_property_readonly("names", &PySequence::names)
      .def_property_readonly("K", &PySequence::intrinsics, "3x3 intrinsics (cam_K.txt)")
      .def("read", &PySequence::read, py::arg("i"), "(rgb uint8 BGR, depth float32 metres, mask uint8 or None) of frame i")
      .def_property_readonly("objects", &PySequence::objects,
                             "names of the objects of a sequence of several (masks/<object>/ or labels/objects.txt); "
                             "[] for one object")
      .def("masks", &PySequence::masks, py::arg("i"), "{object: HxW uint8 mask or None} of frame i (several objects)")
      .def_property_readonly("has_ground_truth", &PySequence::hasGroundTruth)
      .def("ground_truth", &PySequence::groundTruth, py::arg("i"), py::arg("object") = "",
           "4x4 annotated T_cam_obj of frame i (of `object` among several)")
      .def_property_readonly("has_model", &PySequence::hasModel)
      .def("model_points", &PySequence::modelPoints, py::arg("object") = "",
           "Nx3 float32 object points (model/points.xyz, model/<object>/points.xyz)");

  py::class_<PyMultiTracker>(m, "MultiTracker",
                             "MultiTracker(objects, K, config=None): several objects in one camera, each with a tracker "
                             "of its own (config as for Tracker), every frame preprocessed once for all of them")
      .def(py::init<std::vector<std::string>, const py::handle&, const py::object&>(), py::arg("objects"), py::arg("K"),
           py::arg("config") = py::none())
      .def("track", &PyMultiTracker::track, py::arg("rgb"), py::arg("depth"), py::arg("masks"),
           py::arg("poses") = py::none(),
           "One frame for every object: rgb and depth as for Tracker, masks {name: HxW mask} (a name left out or "
           "None sits the frame out, or follows its own masks once started with masks.source 'propagated'), poses "
           "{name: 4x4 T_cam_obj} where an object starts (identity). An object starts with its first non-empty "
           "mask. Returns {name: Result, or None while it has not started or sits the frame out}")
      .def("object_model", &PyMultiTracker::objectModel, py::arg("object"), "the object's model, as Tracker.object_model")
      .def_property_readonly("objects", &PyMultiTracker::objects)
      .def_property_readonly("started", &PyMultiTracker::started, "{name: whether the object has started}")
      .def_property_readonly("frames", &PyMultiTracker::frames, "frames seen so far");

  m.def("score", &score, py::arg("model"), py::arg("truth"), py::arg("estimates"),
        "ADD / ADD-S AUC (0-10 cm, x100), 5deg5cm and IoU25 (%), mean errors, over the frames; an estimate of "
        "None counts as a failure");
  m.def("rotation_error_deg", [](const py::handle& a, const py::handle& b) {
    return bt::rotationErrorDeg(poseArgument(a, "T_true"), poseArgument(b, "T_est"));
  }, py::arg("T_true"), py::arg("T_est"));
  m.def("translation_error", [](const py::handle& a, const py::handle& b) {
    return bt::translationError(poseArgument(a, "T_true"), poseArgument(b, "T_est"));
  }, py::arg("T_true"), py::arg("T_est"), "metres");
}
