#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "bundletrack/core/execution.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/masks/propagated_masks.hpp"
#include "bundletrack/registration/ransac.hpp"
#include "bundletrack/residuals/dense_photometric.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/residuals/dense_silhouette.hpp"
#include "bundletrack/robust/losses.hpp"
#include "bundletrack/solvers/pcg.hpp"
#include "bundletrack/tracking/tracker_settings.hpp"
#include "bundletrack/verification/surface_agreement.hpp"

namespace bundletrack {

/// Every run-time choice and setting of a tracker built by makeTracker (bundletrack::runtime) and
/// of the example programs. The defaults are those of the structs each field is: the policies'
/// own settings, so each default lives in one place.
struct Config {
  std::string tracker = "full";  ///< full: pose graph (paper IV) | coarse: frame-to-frame RANSAC
  io::SequenceSettings sequence;
  std::string features = "sift";  ///< sift | orb | akaze
  SiftSettings sift;  ///< with the settings every detector shares (max_keypoints, crop, matching)
  OrbSettings orb;
  AkazeSettings akaze;
  RansacSettings ransac;
  TrackerSettings tracking;
  SurfaceAgreementSettings verification;
  HuberLoss feature_loss;
  HuberLoss dense_loss;
  DensePointToPlane dense;
  DensePhotometric photometric;
  HuberLoss photometric_loss{DensePhotometric::kHuberDelta};
  double photometric_weight = 1.0;  ///< lambda of the photometric term (0: off)
  DenseSilhouette silhouette;
  HuberLoss silhouette_loss{DenseSilhouette::kHuberDelta};
  double silhouette_weight = 1.0;  ///< lambda of the silhouette term (0: off)
  PCG pcg;
  std::string masks = "given";  ///< given | propagated
  bool drop_mask_background = true;  ///< given masks: GivenMaskSettings::drop_background
  PropagatedMaskSettings propagated_masks;
  std::string device = "cpu";  ///< cpu | gpu
  Execution execution = Execution::Parallel;
};

/// A setting chosen by name among `names`, read and written as text.
struct ConfigChoice {
  std::vector<std::string> names;
  std::function<std::string()> get;
  std::function<void(const std::string&)> set;

  /// The names, e.g. "sift | orb | akaze".
  std::string alternatives(const char* separator = " | ") const {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : separator) + n;
    return out;
  }
};

/// One setting: section.key, where it lives (a number of some type, or a choice), its valid range
/// (numbers), unit and meaning. The table of them (configEntries) is what the YAML reader, the
/// printer and the README's reference table are made from.
struct ConfigEntry {
  const char* section;
  const char* key;
  std::variant<int*, float*, double*, std::size_t*, ConfigChoice> value;
  double min, max;
  const char* unit;
  const char* meaning;

  std::string name() const { return std::string(section) + "." + key; }
};

namespace detail {

inline ConfigChoice textChoice(std::string& value, std::vector<std::string> names) {
  return {std::move(names), [&value] { return value; }, [&value](const std::string& name) { value = name; }};
}

template <typename Enum>
ConfigChoice enumChoice(Enum& value, std::vector<std::pair<std::string, Enum>> options) {
  std::vector<std::string> names;
  for (const auto& option : options) names.push_back(option.first);
  return {std::move(names),
          [&value, options] {
            for (const auto& [name, option] : options)
              if (option == value) return name;
            return std::string("?");
          },
          [&value, options](const std::string& name) {
            for (const auto& [option_name, option] : options)
              if (option_name == name) value = option;
          }};
}

/// The sensor's preset: setting a name loads its numbers, which the sensor.* keys then refine.
/// Read back, a sensor whose numbers were refined names the preset sharing most of them (so the
/// printed configuration, preset then numbers, reads back to the same sensor).
inline ConfigChoice sensorChoice(DepthNoise& sensor) {
  const std::vector<std::pair<std::string, DepthNoise>> presets = {{"structured_light", DepthNoise::structuredLight()},
                                                                   {"active_stereo", DepthNoise::activeStereo()},
                                                                   {"time_of_flight", DepthNoise::timeOfFlight()}};
  const auto shared = [](const DepthNoise& a, const DepthNoise& b) {
    return (a.base == b.base) + (a.linear == b.linear) + (a.quadratic == b.quadratic) + (a.offset == b.offset) +
           (a.subpixel == b.subpixel) + (a.baseline == b.baseline) + (a.disparity_step == b.disparity_step) +
           (a.max_range == b.max_range);
  };
  std::vector<std::string> names;
  for (const auto& preset : presets) names.push_back(preset.first);
  return {std::move(names),
          [&sensor, presets, shared] {
            const auto nearest = std::max_element(presets.begin(), presets.end(), [&](const auto& a, const auto& b) {
              return shared(a.second, sensor) < shared(b.second, sensor);
            });
            return nearest->first;
          },
          [&sensor, presets](const std::string& name) {
            for (const auto& [preset_name, preset] : presets)
              if (preset_name == name) sensor = preset;
          }};
}

}  // namespace detail

/// The table of every setting of `c`, in the order they are printed and documented.
inline std::vector<ConfigEntry> configEntries(Config& c) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto& depth = c.sequence.frame.depth_filter;
  auto& t = c.tracking;
  auto& m = c.propagated_masks;
  auto& sensor = c.sequence.frame.sensor;
  using detail::enumChoice, detail::textChoice;
  return {
      {"tracker", "type", textChoice(c.tracker, {"full", "coarse"}), 0, 0, "",
       "full: pose graph over keyframes (paper IV); coarse: frame-to-frame RANSAC only"},
      {"sequence", "layout", enumChoice(c.sequence.layout, {{"auto", io::Layout::Auto}, {"ycbineoat", io::Layout::YcbInEoat}, {"tum", io::Layout::Tum}}), 0, 0, "",
       "how the folder lists its frames: ycbineoat (rgb/, depth/ by name), tum (rgb.txt, depth.txt by time); auto: tum where rgb.txt and depth.txt exist"},
      {"sequence", "max_time_difference", &c.sequence.max_time_difference, 0.0, 10.0, "s", "tum: a colour image's depth image is the nearest in time within this"},
      {"depth", "scale", &c.sequence.depth_scale, 0.0, 1.0, "m/unit", "metres per unit of the 16-bit depth images; 0: the layout's (ycbineoat 0.001, tum 1/5000; numpy arrays 0.001)"},
      {"depth", "min_depth", &depth.min_depth, 0.0, 100.0, "m", "closer readings are invalid"},
      {"depth", "max_depth", &depth.max_depth, 0.0, inf, "m", "farther readings are invalid"},
      {"depth", "erode_radius", &depth.erode_radius, 0, 10, "px", "erosion neighbourhood radius (1: 3x3)"},
      {"depth", "erode_depth_diff", &depth.erode_depth_diff, 0.0, 1.0, "m", "a neighbour farther in depth than this and than 3 sigma of two readings' difference counts against a pixel"},
      {"depth", "erode_ratio", &depth.erode_ratio, 0.0, 1.0, "", "fraction of neighbours against a pixel that removes it"},
      {"depth", "smooth_radius", &depth.smooth_radius, 0, 10, "px", "smoothing window radius (2: 5x5)"},
      {"depth", "smooth_sigma", &depth.smooth_sigma, 1e-3, 100.0, "px", "spatial Gaussian of the smoothing"},
      {"depth", "smooth_depth_window", &depth.smooth_depth_window, 0.0, 1.0, "m", "only neighbours within this depth of a pixel smooth it"},
      {"depth", "smooth_passes", &depth.smooth_passes, 0, 10, "", "smoothing passes"},
      {"depth", "smoothing", enumChoice(depth.smoothing, {{"mean", DepthSmoothing::Mean}, {"plane_fit", DepthSmoothing::PlaneFit}}), 0, 0, "",
       "mean: each pixel the weighted mean of its neighbours within the window; plane_fit: their weighted plane's value at the pixel"},
      {"depth", "normal_max_depth_jump", &c.sequence.frame.normal_max_depth_jump, 0.0, 1.0, "m", "no normal across a larger depth jump"},
      {"sensor", "model", detail::sensorChoice(sensor), 0, 0, "",
       "depth noise preset (Kinect v1 / Xtion, RealSense D4xx, Azure Kinect): every depth and distance tolerance widens with it beyond Kinect v1 at 1 m (docs/DESIGN.md); the sensor keys below refine it one by one"},
      {"sensor", "base", &sensor.base, 0.0, 1.0, "m", "sigma(z) = base + linear z + quadratic (z - offset)^2 + z^2 subpixel / (f baseline): constant term"},
      {"sensor", "linear", &sensor.linear, 0.0, 1.0, "m/m", "sigma's term proportional to depth (time of flight)"},
      {"sensor", "quadratic", &sensor.quadratic, 0.0, 1.0, "m/m^2", "sigma's term in (z - offset)^2 (structured light)"},
      {"sensor", "offset", &sensor.offset, 0.0, 10.0, "m", "the depth where the quadratic term vanishes"},
      {"sensor", "subpixel", &sensor.subpixel, 0.0, 10.0, "px", "RMS disparity error of a stereo or structured-light match: sigma's term z^2 subpixel / (f baseline)"},
      {"sensor", "baseline", &sensor.baseline, 1e-3, 10.0, "m", "projector-camera or stereo baseline"},
      {"sensor", "disparity_step", &sensor.disparity_step, 0.0, 10.0, "px", "disparity quantisation: readings lie on a grid of depths this many pixels of disparity apart (0: none)"},
      {"sensor", "max_range", &sensor.max_range, 0.0, 1000.0, "m", "farthest depth of the sensor's specification: the depth unit check warns beyond it (0: unknown)"},
      {"features", "type", textChoice(c.features, {"sift", "orb", "akaze"}), 0, 0, "", "keypoint detector and descriptor"},
      {"features", "detect", enumChoice(t.keypoints, {{"every_frame", KeypointSchedule::EveryFrame}, {"on_demand", KeypointSchedule::OnDemand}}), 0, 0, "",
       "every_frame: paper IV; on_demand: a frame is tracked by the dense term alone where its surface holds the pose and the verifier accepts it, keypoints are detected otherwise and on keyframes"},
      {"features", "follow", enumChoice(t.follow_keypoints, {{"optical_flow", true}, {"none", false}}), 0, 0, "",
       "on_demand: where the surface alone cannot hold a frame, the last frame's keypoints are first followed into it by optical flow (none: detected)"},
      {"features", "follow_min_share", &t.follow_min_share, 0.0, 1.0, "", "followed keypoints are kept while RANSAC keeps this share of those the chain of followed frames began with"},
      {"features", "min_surface_stability", &t.min_surface_stability, 0.0, 1.0, "", "on_demand: weakest / strongest direction of the surface's point-to-plane information needed to skip keypoints"},
      {"features", "max_keypoints", &c.sift.max_keypoints, 3, 100000, "", "strongest keypoints kept per frame"},
      {"features", "sift_contrast_threshold", &c.sift.contrast_threshold, 0.0, 1.0, "", "SIFT contrast threshold (original config: 0.01)"},
      {"features", "crop_size", &c.sift.crop.crop_size, 32, 4096, "px", "side of the square object crop the detector runs on"},
      {"features", "mask_dilation", &c.sift.crop.mask_dilation, 0, 100, "px", "the detector sees this much around the mask"},
      {"features", "ratio", &c.sift.matching.ratio, 0.0, 1.0, "", "Lowe's ratio test, both directions"},
      {"ransac", "inlier_distance", &c.ransac.inlier_distance, 1e-5, 1.0, "m", "paper IV-B delta"},
      {"ransac", "inlier_normal_angle_deg", &c.ransac.inlier_normal_angle_deg, 0.0, 180.0, "deg", "paper IV-B alpha"},
      {"ransac", "max_trials", &c.ransac.max_trials, 1, 1000000, "", "cap on hypotheses"},
      {"ransac", "confidence", &c.ransac.confidence, 0.0, 0.999999999, "", "adaptive stop: chance of having missed a better hypothesis"},
      {"ransac", "min_inliers", &t.min_inliers, 3, 100000, "", "fewest inliers with the previous frame for a coarse pose"},
      {"graph", "max_keyframes", &t.max_keyframes, 1, 1000, "", "K: keyframes in the pose graph (paper IV-C)"},
      {"graph", "pool_capacity", &t.pool_capacity, 2, 100000, "", "keyframes kept in memory"},
      {"graph", "new_keyframe_rotation_deg", &t.new_keyframe_rotation_deg, 0.0, 180.0, "deg", "paper IV-E"},
      {"graph", "dense_grid_step", &t.dense_grid_step, 1, 64, "px", "largest step of the surface grids (dense term, verification, masks)"},
      {"graph", "dense_target_samples", &t.dense_target_samples, 1, 10000000, "", "the grid step is chosen from the first mask to sample about this many object points"},
      {"graph", "edge_gate_distance", &t.edge_gate.max_distance, 0.0, 1.0, "m", "feature matches of an edge must agree with the poses"},
      {"graph", "edge_gate_normal_angle_deg", &t.edge_gate.max_normal_angle_deg, 0.0, 180.0, "deg", "same, for normals"},
      {"graph", "min_edge_correspondences", &t.min_edge_correspondences, 3, 100000, "", "fewer: the edge has no feature term"},
      {"graph", "min_agreement", &c.verification.min_agreement, 0.0, 1.0, "", "fraction of overlapping points on a keyframe's surface to accept the graph's pose"},
      {"graph", "agreement_distance", &c.verification.gate.max_distance, 0.0, 1.0, "m", "on the surface: within this distance"},
      {"graph", "agreement_normal_angle_deg", &c.verification.gate.max_normal_angle_deg, 0.0, 180.0, "deg", "on the surface: normals within this angle"},
      {"graph", "recovery_min_inliers", &t.recovery_min_inliers, 3, 100000, "", "RANSAC inliers needed to restart after lost frames; with fewer, a frame whose graph from RANSAC's pose is refused tries the graph from the last good pose (surface evidence) before RANSAC's pose stands"},
      {"graph", "min_kept_coarse_inliers", &t.min_kept_coarse_inliers, 0.0, 1.0, "", "a graph result must keep this share of the coarse pose's RANSAC inliers with the last frame (with recovery_min_inliers or more; 0: no check)"},
      {"graph", "recovery_surface_candidates", &t.recovery_surface_candidates, 0, 100, "", "coarse poses a lost frame tries with its surface alone to confirm them (0: features alone)"},
      {"graph", "recovery_min_agreement", &c.verification.recovery_min_agreement, 0.0, 1.0, "", "agreement such a re-acquisition needs"},
      {"graph", "recovery_turn_step_deg", &t.recovery_turn_step_deg, 0.0, 180.0, "deg", "a lost frame also tries the last good pose turned by multiples of this about each camera axis"},
      {"graph", "recovery_turn_rings", &t.recovery_turn_rings, 0, 100, "", "multiples tried (0: none)"},
      {"graph", "recovery_min_consensus", &t.recovery_min_consensus, 1, 1000, "", "a lost frame's pose reached from this many of its candidates needs only min_agreement"},
      {"graph", "recovery_consensus_angle_deg", &t.recovery_consensus_angle_deg, 0.0, 180.0, "deg", "those poses agree within this angle ..."},
      {"graph", "recovery_consensus_distance", &t.recovery_consensus_distance, 0.0, 1.0, "m", "... and this distance (widened by the sensor's noise)"},
      {"graph", "gauss_newton_iterations", &t.gauss_newton.iterations, 0, 1000, "", "paper IV-D, original code: 7"},
      {"energy", "feature_huber_delta", &c.feature_loss.delta, 1e-6, 1.0, "m", "Huber delta of the feature term (paper eq. 2)"},
      {"energy", "dense_huber_delta", &c.dense_loss.delta, 1e-6, 1.0, "m", "Huber delta of the dense term (paper eq. 3)"},
      {"energy", "dense_max_distance", &c.dense.gate.max_distance, 0.0, 1.0, "m", "dense association: points farther apart are not paired"},
      {"energy", "dense_max_normal_angle_deg", &c.dense.gate.max_normal_angle_deg, 0.0, 180.0, "deg", "dense association: nor normals farther apart"},
      {"energy", "photometric_weight", &c.photometric_weight, 0.0, 1000.0, "", "lambda of the photometric term: brightness constancy of the surface points between frames (0: off)"},
      {"energy", "photometric_sigma", &c.photometric.sigma, 1e-4, 1.0, "", "expected brightness change of a surface point between views (intensity 0-1): the term's weight beside the depth noise"},
      {"energy", "photometric_huber_delta", &c.photometric_loss.delta, 1e-6, 1.0, "", "Huber delta of the photometric term (intensity 0-1)"},
      {"energy", "silhouette_weight", &c.silhouette_weight, 0.0, 1000.0, "", "lambda of the silhouette term: every object point projects inside the object's mask in every frame (0: off)"},
      {"energy", "silhouette_sigma", &c.silhouette.sigma, 1e-3, 100.0, "px", "spread of the masks' outlines: the term's weight beside the depth noise"},
      {"energy", "silhouette_huber_delta", &c.silhouette_loss.delta, 1e-3, 100.0, "px", "Huber delta of the silhouette term"},
      {"solver", "step_control", enumChoice(t.gauss_newton.step_control, {{"none", StepControl::None}, {"levenberg_marquardt", StepControl::LevenbergMarquardt}}), 0, 0, "",
       "none: every Gauss-Newton step is taken (paper); levenberg_marquardt: damped, a step that raises the energy is rejected"},
      {"solver", "min_translation_step", &t.gauss_newton.min_translation_step, 0.0, 1.0, "m", "Gauss-Newton stops when no node moves more ..."},
      {"solver", "min_rotation_step", &t.gauss_newton.min_rotation_step, 0.0, 1.0, "rad", "... and none turns more"},
      {"solver", "relinearise_translation", &t.relinearisation.max_translation, 0.0, 1.0, "m", "an edge between keyframes is linearised again once one moved this far since ... (0 and 0: every step, as the paper)"},
      {"solver", "relinearise_rotation", &t.relinearisation.max_rotation, 0.0, 3.2, "rad", "... or turned this far"},
      {"solver", "pcg_max_iterations", &c.pcg.max_iterations, 1, 100000, "", "PCG iterations per step (original code: 5)"},
      {"solver", "pcg_tolerance", &c.pcg.tolerance, 0.0, 1.0, "", "PCG stops at this relative residual (the GPU's float PCG at 1e-6 at the least)"},
      {"masks", "source", textChoice(c.masks, {"given", "propagated"}), 0, 0, "",
       "given: every frame's mask from the data; propagated: from the first mask alone"},
      {"masks", "background", enumChoice(c.drop_mask_background, {{"drop", true}, {"keep", false}}), 0, 0, "",
       "given: drop: a surface of the mask that reaches its outline and lies wholly behind the mask's largest surface (beyond depth_continuity) is the background the mask took in beside the object, and leaves the mask; keep: the mask as given"},
      {"masks", "search_margin_px", &m.search_margin_px, 0, 10000, "px", "propagated: keypoints are searched this far around the last pose's silhouette"},
      {"masks", "growth_px", &m.growth_px, 0, 10000, "px", "propagated: the mask reaches this far beyond the rendered silhouette"},
      {"masks", "depth_agreement", &m.depth_agreement, 0.0, 1.0, "m", "propagated: observed vs rendered depth that seeds the mask"},
      {"masks", "depth_continuity", &m.depth_continuity, 0.0, 1.0, "m", "largest depth step between neighbouring pixels of one surface (widened by the sensor's noise): propagated masks grow over such steps, given masks drop surfaces behind such a step"},
      {"masks", "hull_dilation_px", &m.hull_dilation_px, 0, 1000, "px", "propagated: slack of the first view's silhouette"},
      {"masks", "hull_depth_tolerance", &m.hull_depth_tolerance, 0.0, 1.0, "m", "propagated: slack in front of the first view's surface"},
      {"masks", "object_size_factor", &m.object_size_factor, 0.0, 100.0, "", "propagated, after lost: searched surfaces are at most this times the first view's extent"},
      {"masks", "min_area_fraction", &m.min_area_fraction, 0.0, 1.0, "", "propagated, after lost: and show this fraction of the first view's area"},
      {"masks", "support", enumChoice(m.stop_at_support, {{"plane", true}, {"none", false}}), 0, 0, "",
       "propagated: plane: the mask stays off the surface the object rested on in the first frame (if it rested on one; near it only pixels coloured as the first mask join, or only seeds where colour cannot tell); none: no such rule"},
      {"compute", "device", textChoice(c.device, {"cpu", "gpu"}), 0, 0, "",
       "cpu: header-only policies; gpu: matching, dense term, PCG and RANSAC on a CUDA device (bundletrack::cuda; keypoints are still detected on the CPU)"},
      {"compute", "execution", enumChoice(c.execution, {{"parallel", Execution::Parallel}, {"serial", Execution::Serial}}), 0, 0, "",
       "parallel: edges and RANSAC trials on all cores; serial: one thread (the same poses either way)"},
  };
}

}  // namespace bundletrack
