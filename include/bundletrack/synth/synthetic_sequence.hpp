#pragma once

#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/imgcodecs.hpp>

#include "bundletrack/core/error.hpp"
#include "bundletrack/io/point_files.hpp"
#include "bundletrack/io/pose_files.hpp"
#include "bundletrack/io/sequence_layouts.hpp"
#include "bundletrack/synth/renderer.hpp"
#include "bundletrack/synth/sensor_model.hpp"
#include "bundletrack/synth/trajectory.hpp"

namespace bundletrack::synth {

enum class Shape { Box, Cylinder, Mug, Chair };
enum class Motion { HandHeld, CameraOrbit };

inline const char* shapeName(Shape shape) {
  switch (shape) {
    case Shape::Cylinder: return "cylinder";
    case Shape::Mug: return "mug";
    case Shape::Chair: return "chair";
    default: return "box";
  }
}

/// How the written masks err from the objects' true outlines, as a segmentation's masks or a
/// depth-to-colour registration do (the ground truth is unchanged).
enum class MaskError {
  None,
  Dilated,  ///< grown by mask_error_px: the mask bleeds onto what lies behind the object
  Eroded,  ///< shrunk by mask_error_px: the mask misses the object's rim
  Shifted,  ///< moved mask_error_px to the right: both at once, on either side
};

struct SyntheticSequenceSettings {
  int frames = 300;
  cv::Size image_size{640, 480};
  PinholeCamerad camera{600.0, 600.0, 319.5, 239.5};
  Shape shape = Shape::Box;
  bool textureless = false;  ///< one flat colour instead of the printed texture
  Motion motion = Motion::HandHeld;
  double speed = 1.0;  ///< scales the motion's phase rate (see HandHeldMotion)
  /// Metres from the camera to the object (hand-held: to the centre of its motion; orbit: at the
  /// start, the whole orbit scaled about the object); 0: the motion's own, 0.73 m hand-held and
  /// 0.5-0.7 m orbiting.
  double distance = 0.0;
  /// The object's size: the diagonal of its bounding box in metres (the mesh scaled uniformly);
  /// 0: the shape's own (box 0.20 m, can 0.15 m, mug 0.17 m, chair 0.83 m).
  double size = 0.0;
  bool occluder = false;  ///< an arm passes between camera and object around the middle frame
  int hidden_start = -1;  ///< from this frame the hand carries the object out of view (-1: never) ...
  int hidden_frames = 0;  ///< ... for this many frames; it comes back where its motion has taken it
  int motion_blur_samples = 1;  ///< > 1: colour averaged over this many instants of a half-frame exposure
  /// 1-3 objects. The others are the first of box, cylinder, mug that the first object is not,
  /// each with its own texture and hand-held motion: the second sweeps sideways in front of the
  /// first object, the third behind it, so that they occlude each other. (Hand-held motion only.)
  int objects = 1;
  MaskError mask_error = MaskError::None;
  int mask_error_px = 3;  ///< pixels, with a mask_error
  SensorSettings sensor;
  unsigned seed = 1;
  int model_points = 4000;  ///< surface samples written to model/points.xyz
};

/// Where one object of a frame is: its visible pixels and its exact pose.
struct ObjectView {
  cv::Mat mask;  ///< CV_8UC1 255 where the object is the visible surface
  SE3d T_cam_obj;
};

/// One rendered frame with its exact ground truth.
struct SyntheticFrame {
  cv::Mat color;  ///< CV_8UC3 BGR, with sensor noise
  cv::Mat depth;  ///< CV_32FC1 metres, with the sensor model applied; 0 = no reading
  cv::Mat mask;  ///< CV_8UC1 255 where the (first) object is the visible surface
  SE3d T_cam_obj;  ///< of the (first) object
  std::vector<ObjectView> others;  ///< the other objects (SyntheticSequenceSettings::objects)
};

/// The scene of a synthetic sequence: object(s), table, wall, optional occluder and their motion.
class SyntheticScene {
 public:
  static constexpr int kTable = 0, kWall = 1, kObject = 2, kOccluder = 3;
  /// Render label of object k (0: the first object, kObject).
  static constexpr int objectLabel(int k) { return k == 0 ? kObject : kOccluder + k; }

  explicit SyntheticScene(SyntheticSequenceSettings settings)
      : s_(std::move(settings)),
        renderer_(s_.camera, s_.image_size),
        object_mesh_(makeObjectMesh(s_.shape, s_.size)),
        occluder_mesh_(makeCylinder(0.035, 0.9, 32)),
        object_texture_(s_.textureless ? plainTexture({60, 140, 200}) : richTexture(1024, s_.seed)),
        table_texture_(noiseTexture(512, s_.seed + 11, 0.8)),
        wall_texture_(richTexture(512, s_.seed + 23)),
        occluder_texture_(noiseTexture(128, s_.seed + 37, 0.3)) {
    if (s_.frames <= 0) throw InputError("synthetic sequence", "frames must be positive");
    if (!(s_.speed > 0.0)) throw InputError("synthetic sequence", "speed must be positive");
    if (!(s_.distance >= 0.0) || s_.distance > 10.0)
      throw InputError("synthetic sequence", "distance must be 0 (the motion's own) or up to 10 m");
    if (!(s_.size >= 0.0) || s_.size > 5.0)
      throw InputError("synthetic sequence", "size must be 0 (the shape's own) or up to 5 m");
    if (s_.motion_blur_samples < 1) throw InputError("synthetic sequence", "motion_blur_samples must be >= 1");
    if (s_.objects < 1 || s_.objects > 3) throw InputError("synthetic sequence", "objects must be 1, 2 or 3");
    if (s_.mask_error != MaskError::None && (s_.mask_error_px < 1 || s_.mask_error_px > 50))
      throw InputError("synthetic sequence", "mask_error_px must be 1 to 50");
    if (s_.objects > 1 && s_.motion != Motion::HandHeld)
      throw InputError("synthetic sequence", "several objects move only by hand (hand-held motion)");
    for (const Shape shape : {Shape::Box, Shape::Cylinder, Shape::Mug}) {
      if (int(others_.size()) + 1 == s_.objects) break;
      if (shape == s_.shape) continue;
      const unsigned seed = s_.seed + 101u * unsigned(others_.size() + 1);
      others_.push_back({shape, makeObjectMesh(shape, 0.0), s_.textureless ? plainTexture({200, 120, 70}) : richTexture(512, seed)});
    }
  }

  const SyntheticSequenceSettings& settings() const { return s_; }
  int objectCount() const { return 1 + int(others_.size()); }
  const TriangleMesh& objectMesh(int k = 0) const { return k == 0 ? object_mesh_ : others_.at(std::size_t(k - 1)).mesh; }
  Shape objectShape(int k = 0) const { return k == 0 ? s_.shape : others_.at(std::size_t(k - 1)).shape; }
  /// The folder name of object k's masks, poses and model in a sequence of several objects.
  std::string objectName(int k) const { return shapeName(objectShape(k)); }

  /// Object k's pose in the world. The other objects (k > 0) are carried by their own hands: the
  /// hand-held motion shifted in phase, about a centre that sweeps 15 cm to either side 12 cm in
  /// front of the first object's (k = 1) or 12 cm behind it (k = 2), on the camera's line of
  /// sight, so that they pass in front of each other.
  SE3d T_world_obj(double frame, int k = 0) const {
    if (k > 0) {
      HandHeldMotion hand;
      const double phase = motionPhase(frame, s_.speed), nearer = k == 1 ? 0.12 : -0.12;
      const Eigen::Vector3d towards_camera = (hand.eye - hand.centre).normalized();
      hand.centre += nearer * towards_camera + Eigen::Vector3d(0.15 * std::cos(1.3 * phase + 0.4 * k), 0.0, 0.0);
      return hand.T_world_obj(frame + 70.0 * k, s_.speed);
    }
    if (s_.motion == Motion::HandHeld) {
      SE3d T = HandHeldMotion().T_world_obj(frame, s_.speed);
      if (frame >= s_.hidden_start && frame < s_.hidden_start + s_.hidden_frames)
        T = SE3d(T.rotation(), T.translation() + Eigen::Vector3d(2.0, 0.0, 0.0));  // far outside the view
      return T;
    }
    return SE3d(SO3d(), Eigen::Vector3d(0.0, 0.0, restingHeight()));
  }

  SE3d T_world_cam(double frame) const {
    if (s_.motion == Motion::HandHeld) {
      const HandHeldMotion motion;
      return s_.distance > 0.0 ? motion.cameraAt(s_.distance) : motion.T_world_cam;
    }
    const Eigen::Vector3d target = T_world_obj(frame).translation();
    const SE3d T = CameraOrbitMotion().T_world_cam(frame, s_.speed, target);
    if (s_.distance <= 0.0) return T;
    // The whole orbit scaled about the object so that it starts `distance` away.
    const double scale = s_.distance / (CameraOrbitMotion().T_world_cam(0.0, s_.speed, target).translation() - target).norm();
    return SE3d(T.rotation(), target + scale * (T.translation() - target));
  }

  SE3d T_cam_obj(double frame, int k = 0) const { return T_world_cam(frame).inverse() * T_world_obj(frame, k); }

  /// Noise-free render at a (possibly fractional) frame time.
  RenderBuffers renderClean(double frame, bool with_object = true) const {
    const SE3d T_cam_world = T_world_cam(frame).inverse();
    const auto plane = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& u, const Eigen::Vector3d& v, double tile,
                           const cv::Mat& texture, int label) {
      return TexturedPlane{T_cam_world * o, T_cam_world.rotation() * u, T_cam_world.rotation() * v, tile, &texture,
                           label};
    };
    const std::vector<TexturedPlane> planes = {
        plane({0, 0, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 0.6, table_texture_, kTable),
        plane({-1.0, 1.0, 1.2}, Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ(), 2.0, wall_texture_, kWall)};
    std::vector<MeshInstance> meshes;
    if (with_object) meshes.push_back({&object_mesh_, &object_texture_, T_cam_obj(frame), kObject});
    for (int k = 1; k < objectCount(); ++k) {
      const OtherObject& other = others_[std::size_t(k - 1)];
      meshes.push_back({&other.mesh, &other.texture, T_cam_obj(frame, k), objectLabel(k)});
    }
    if (const auto T_cam_occluder = occluderPose(frame)) {
      meshes.push_back({&occluder_mesh_, &occluder_texture_, T_cam_world * *T_cam_occluder, kOccluder});
    }
    return renderer_.render(planes, meshes);
  }

  SyntheticFrame frame(int i) const {
    RenderBuffers clean = renderClean(i);
    if (s_.motion_blur_samples > 1) {
      cv::Mat sum(clean.color.size(), CV_32FC3, cv::Scalar::all(0));
      for (int k = 0; k < s_.motion_blur_samples; ++k)
        sum += renderClean(i + 0.5 * (double(k) / (s_.motion_blur_samples - 1) - 0.5)).color;
      clean.color = sum / double(s_.motion_blur_samples);
    }
    SyntheticFrame out;
    applySensorModel(clean, s_.camera, s_.sensor, s_.seed * 100003u + unsigned(i), out.depth, out.color);
    out.mask = writtenMask(clean.label == kObject);
    out.T_cam_obj = T_cam_obj(i);
    for (int k = 1; k < objectCount(); ++k) out.others.push_back({writtenMask(clean.label == objectLabel(k)), T_cam_obj(i, k)});
    return out;
  }

  /// An object's mask as the sequence gives it: its true visible pixels with the settings' MaskError.
  cv::Mat writtenMask(const cv::Mat& visible) const {
    const int px = s_.mask_error_px;
    const cv::Mat disc = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * px + 1, 2 * px + 1));
    cv::Mat mask;
    switch (s_.mask_error) {
      case MaskError::Dilated: cv::dilate(visible, mask, disc); return mask;
      case MaskError::Eroded: cv::erode(visible, mask, disc); return mask;
      case MaskError::Shifted:
        mask = cv::Mat::zeros(visible.size(), CV_8UC1);
        if (px < visible.cols) visible.colRange(0, visible.cols - px).copyTo(mask.colRange(px, visible.cols));
        return mask;
      default: return visible;
    }
  }

 private:
  static TriangleMesh makeShape(Shape shape) {
    switch (shape) {
      case Shape::Cylinder: return makeCylinder(0.035, 0.11);
      case Shape::Mug: return makeMug(0.04, 0.095, 0.006);
      case Shape::Chair: return makeChair();
      default: return makeBox({0.10, 0.07, 0.16});
    }
  }

  /// The shape, scaled about its origin so that its bounding-box diagonal is `size` (0: as it is).
  static TriangleMesh makeObjectMesh(Shape shape, double size) {
    TriangleMesh mesh = makeShape(shape);
    if (size <= 0.0) return mesh;
    Eigen::AlignedBox3d bounds;
    for (const auto& p : mesh.positions) bounds.extend(p);
    const double scale = size / bounds.diagonal().norm();
    for (auto& p : mesh.positions) p *= scale;
    return mesh;
  }

  double restingHeight() const {
    double lowest = 0.0;
    for (const auto& p : object_mesh_.positions) lowest = std::min(lowest, p.z());
    return -lowest;
  }

  /// The occluding arm: a vertical cylinder halfway between camera and object that sweeps 50 cm
  /// sideways over the 40 frames around the middle of the sequence.
  std::optional<SE3d> occluderPose(double frame) const {
    const double start = 0.5 * s_.frames - 20.0, duration = 40.0;
    if (!s_.occluder || frame < start || frame > start + duration) return std::nullopt;
    const SE3d T_world_cam = this->T_world_cam(frame);
    const Eigen::Vector3d middle = 0.5 * (T_world_cam.translation() + T_world_obj(frame).translation());
    const Eigen::Vector3d sideways = T_world_cam.rotation() * Eigen::Vector3d::UnitX();
    const double progress = (frame - start) / duration;
    return SE3d(SO3d(), middle + (progress - 0.5) * 0.5 * sideways);
  }

  struct OtherObject {
    Shape shape;
    TriangleMesh mesh;
    cv::Mat texture;
  };

  SyntheticSequenceSettings s_;
  Renderer renderer_;
  TriangleMesh object_mesh_, occluder_mesh_;
  cv::Mat object_texture_, table_texture_, wall_texture_, occluder_texture_;
  std::vector<OtherObject> others_;
};

namespace detail {

inline void writeImage(const std::filesystem::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw InputError(path, "cannot write image");
}

}  // namespace detail

/// The TUM RGB-D layout's timestamps of frame i: a 30 Hz colour stream, and depth 4 ms after
/// it (the streams of a Kinect are not synchronised).
inline double tumColorTime(int i) { return 1305031102.0 + i / 30.0; }
inline double tumDepthTime(int i) { return tumColorTime(i) + 0.004; }

inline std::string tumName(double time) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6f", time);
  return buffer;
}

/// How a scene of several objects stores their masks.
enum class MaskFiles {
  Folders,  ///< masks/<object>/<name>.png
  LabelImages,  ///< labels/<name>.png, object k labelled k + 1, named in labels/objects.txt
};

/// Where object k's masks, poses and model go: masks/, annotated_poses/, model/ themselves for a
/// single object, their subfolder <object name> when the scene has several.
inline std::filesystem::path objectFolder(const std::filesystem::path& folder, const SyntheticScene& scene, int k) {
  return scene.objectCount() == 1 ? folder : folder / scene.objectName(k);
}

/// Writes frame i of `scene` under root: named %06d with depth in millimetres (YCBInEOAT), or by
/// its timestamps with depth in 1/5000 m (TUM).
inline void writeFrame(const std::filesystem::path& root, const SyntheticScene& scene, int i, io::Layout layout,
                       MaskFiles mask_files = MaskFiles::Folders) {
  const SyntheticFrame frame = scene.frame(i);
  const bool tum = layout == io::Layout::Tum;
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "%06d", i);
  const std::string name = tum ? tumName(tumColorTime(i)) : std::string(buffer);
  cv::Mat depth_units;
  frame.depth.convertTo(depth_units, CV_16UC1, tum ? 5000.0 : 1000.0);  // rounds to the nearest unit
  detail::writeImage(root / "rgb" / (name + ".png"), frame.color);
  detail::writeImage(root / "depth" / ((tum ? tumName(tumDepthTime(i)) : name) + ".png"), depth_units);
  cv::Mat labels = cv::Mat::zeros(frame.mask.size(), CV_8UC1);
  for (int k = 0; k < scene.objectCount(); ++k) {
    const ObjectView view = k == 0 ? ObjectView{frame.mask, frame.T_cam_obj} : frame.others[std::size_t(k - 1)];
    if (mask_files == MaskFiles::LabelImages) labels.setTo(k + 1, view.mask);
    else detail::writeImage(objectFolder(root / "masks", scene, k) / (name + ".png"), view.mask);
    io::writePose(objectFolder(root / "annotated_poses", scene, k) / (name + ".txt"), view.T_cam_obj);
  }
  if (mask_files == MaskFiles::LabelImages) detail::writeImage(root / "labels" / (name + ".png"), labels);
}

/// Writes the sequence in the YCBInEOAT layout (rgb/, depth/ uint16 mm, masks/, annotated_poses/,
/// cam_K.txt, model/points.xyz), or in the TUM RGB-D layout (the same with rgb.txt and depth.txt
/// listing timestamped images, depth in 1/5000 m); a scene of several objects has a subfolder per
/// object in masks/, annotated_poses/ and model/ (objectFolder), or with MaskFiles::LabelImages
/// one label image per frame in labels/ instead of masks/. A sequence already in `root` is
/// replaced, not mixed with the new one: those folders and lists are removed first (a reader would
/// otherwise take an earlier, longer sequence's frames for this one's). Frames are rendered in
/// parallel; the result depends only on the settings.
inline void writeSyntheticSequence(const std::filesystem::path& root, const SyntheticSequenceSettings& settings,
                                   io::Layout layout = io::Layout::YcbInEoat, MaskFiles mask_files = MaskFiles::Folders) {
  const SyntheticScene scene(settings);
  if (mask_files == MaskFiles::LabelImages && scene.objectCount() == 1)
    throw InputError(root, "label images are for scenes of several objects");
  for (const char* written : {"rgb", "depth", "masks", "labels", "annotated_poses", "model", "rgb.txt", "depth.txt"})
    std::filesystem::remove_all(root / written);
  for (const char* dir : {"rgb", "depth"}) std::filesystem::create_directories(root / dir);
  for (int k = 0; k < scene.objectCount(); ++k)
    for (const char* dir : {"masks", "annotated_poses", "model"})
      if (std::string(dir) != "masks" || mask_files == MaskFiles::Folders)
        std::filesystem::create_directories(objectFolder(root / dir, scene, k));
  if (mask_files == MaskFiles::LabelImages) {
    std::filesystem::create_directories(root / "labels");
    std::ofstream names(root / "labels" / "objects.txt");
    names << "# label object\n";
    for (int k = 0; k < scene.objectCount(); ++k) names << k + 1 << ' ' << scene.objectName(k) << '\n';
    if (!names) throw InputError(root / "labels" / "objects.txt", "cannot write file");
  }
  if (layout == io::Layout::Tum) {
    std::ofstream rgb(root / "rgb.txt"), depth(root / "depth.txt");
    rgb << "# color images\n# timestamp filename\n";
    depth << "# depth maps\n# timestamp filename\n";
    for (int i = 0; i < settings.frames; ++i) {
      rgb << tumName(tumColorTime(i)) << " rgb/" << tumName(tumColorTime(i)) << ".png\n";
      depth << tumName(tumDepthTime(i)) << " depth/" << tumName(tumDepthTime(i)) << ".png\n";
    }
    if (!rgb || !depth) throw InputError(root, "cannot write rgb.txt or depth.txt");
  }
  {
    std::ofstream K(root / "cam_K.txt");
    K.precision(10);
    K << settings.camera.fx << " 0 " << settings.camera.cx << "\n0 " << settings.camera.fy << ' ' << settings.camera.cy
      << "\n0 0 1\n";
    if (!K) throw InputError(root / "cam_K.txt", "cannot write file");
  }
  for (int k = 0; k < scene.objectCount(); ++k)
    io::writePoints(objectFolder(root / "model", scene, k) / "points.xyz",
                    scene.objectMesh(k).sampleSurface(settings.model_points, settings.seed));
  std::mutex error_mutex;
  std::exception_ptr first_error;
  cv::parallel_for_(cv::Range(0, settings.frames), [&](const cv::Range& range) {
    try {
      for (int i = range.start; i < range.end; ++i) writeFrame(root, scene, i, layout, mask_files);
    } catch (...) {
      const std::lock_guard lock(error_mutex);
      if (!first_error) first_error = std::current_exception();
    }
  });
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace bundletrack::synth
