#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/error.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/io/ycbineoat_sequence.hpp"
#include "bundletrack/tracker.hpp"

namespace bundletrack::io {

/// Every setting of the example tracker, with the defaults of DESIGN.md section 3.
struct Config {
  SequenceSettings sequence;
  std::string features = "sift";  ///< sift | orb | akaze
  SiftSettings sift;
  OrbSettings orb;
  AkazeSettings akaze;
  TrackerSettings tracker;
  std::string masks = "given";  ///< given: every frame's mask from the data | propagated: the first one only
  PropagatedMaskSettings propagated_masks;
  std::string device = "cpu";  ///< cpu: the header-only policies | gpu: those of bundletrack::cuda
};

/// A setting chosen by name: section.key, where it lives, and the names it accepts.
struct ConfigChoice {
  const char* section;
  const char* key;
  std::string* value;
  std::vector<std::string> names;
  const char* meaning;
};

inline std::vector<ConfigChoice> configChoices(Config& c) {
  return {{"features", "type", &c.features, {"sift", "orb", "akaze"}, "keypoint detector and descriptor"},
          {"masks", "source", &c.masks, {"given", "propagated"},
           "given: every frame's mask from the data; propagated: from the first mask alone"},
          {"compute", "device", &c.device, {"cpu", "gpu"},
           "cpu: header-only policies; gpu: matching, dense term, PCG and RANSAC on a CUDA device "
           "(bundletrack::cuda; keypoints are still detected on the CPU)"}};
}

/// One entry of the YAML file: section.key, where it lives, its valid range, unit and meaning.
struct ConfigParameter {
  const char* section;
  const char* key;
  std::variant<int*, float*, double*, std::size_t*> value;
  double min, max;
  const char* unit;
  const char* meaning;
};

/// The table behind loading, printing and documenting the configuration.
inline std::vector<ConfigParameter> configParameters(Config& c) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto& depth = c.sequence.frame.depth_filter;
  auto& t = c.tracker;
  auto& m = c.propagated_masks;
  return {
      {"depth", "scale", &c.sequence.depth_scale, 1e-6, 1.0, "m/unit", "metres per unit of the 16-bit depth images"},
      {"depth", "min_depth", &depth.min_depth, 0.0, 100.0, "m", "closer readings are invalid"},
      {"depth", "max_depth", &depth.max_depth, 0.0, inf, "m", "farther readings are invalid"},
      {"depth", "erode_radius", &depth.erode_radius, 0, 10, "px", "erosion neighbourhood radius (1: 3x3)"},
      {"depth", "erode_depth_diff", &depth.erode_depth_diff, 0.0, 1.0, "m", "a neighbour this far in depth counts against a pixel"},
      {"depth", "erode_ratio", &depth.erode_ratio, 0.0, 1.0, "", "fraction of neighbours against a pixel that removes it"},
      {"depth", "smooth_radius", &depth.smooth_radius, 0, 10, "px", "smoothing window radius (2: 5x5)"},
      {"depth", "smooth_sigma", &depth.smooth_sigma, 1e-3, 100.0, "px", "spatial Gaussian of the smoothing"},
      {"depth", "smooth_depth_window", &depth.smooth_depth_window, 0.0, 1.0, "m", "neighbours within this depth of a pixel are averaged"},
      {"depth", "smooth_passes", &depth.smooth_passes, 0, 10, "", "smoothing passes"},
      {"depth", "normal_max_depth_jump", &c.sequence.frame.normal_max_depth_jump, 0.0, 1.0, "m", "no normal across a larger depth jump"},
      {"features", "max_keypoints", &c.sift.max_keypoints, 3, 100000, "", "strongest keypoints kept per frame (SIFT)"},
      {"features", "sift_contrast_threshold", &c.sift.contrast_threshold, 0.0, 1.0, "", "SIFT contrast threshold (original config: 0.01)"},
      {"features", "crop_size", &c.sift.crop.crop_size, 32, 4096, "px", "side of the square object crop the detector runs on"},
      {"features", "mask_dilation", &c.sift.crop.mask_dilation, 0, 100, "px", "the detector sees this much around the mask"},
      {"features", "ratio", &c.sift.matching.ratio, 0.0, 1.0, "", "Lowe's ratio test, both directions"},
      {"ransac", "inlier_distance", &t.coarse.ransac.inlier_distance, 1e-5, 1.0, "m", "paper IV-B delta"},
      {"ransac", "inlier_normal_angle_deg", &t.coarse.ransac.inlier_normal_angle_deg, 0.0, 180.0, "deg", "paper IV-B alpha"},
      {"ransac", "max_trials", &t.coarse.ransac.max_trials, 1, 1000000, "", "cap on hypotheses"},
      {"ransac", "confidence", &t.coarse.ransac.confidence, 0.0, 0.999999999, "", "adaptive stop: chance of having missed a better hypothesis"},
      {"ransac", "min_inliers", &t.coarse.min_inliers, 3, 100000, "", "fewest inliers with the previous frame for a coarse pose"},
      {"graph", "max_keyframes", &t.max_keyframes, 1, 1000, "", "K: keyframes in the pose graph (paper IV-C)"},
      {"graph", "pool_capacity", &t.pool_capacity, 2, 100000, "", "keyframes kept in memory"},
      {"graph", "new_keyframe_rotation_deg", &t.new_keyframe_rotation_deg, 0.0, 180.0, "deg", "paper IV-E"},
      {"graph", "dense_grid_step", &t.dense_grid_step, 1, 64, "px", "the dense term runs on the image downsampled by this"},
      {"graph", "edge_gate_distance", &t.edge_gate_distance, 0.0, 1.0, "m", "feature matches of an edge must agree with the poses"},
      {"graph", "edge_gate_normal_angle_deg", &t.edge_gate_normal_angle_deg, 0.0, 180.0, "deg", "same, for normals"},
      {"graph", "min_edge_correspondences", &t.min_edge_correspondences, 3, 100000, "", "fewer: the edge has no feature term"},
      {"graph", "min_agreement", &t.min_agreement, 0.0, 1.0, "", "fraction of overlapping points on a keyframe's surface to accept the graph's pose"},
      {"graph", "agreement_distance", &t.agreement_distance, 0.0, 1.0, "m", "on the surface: within this distance"},
      {"graph", "recovery_min_inliers", &t.recovery_min_inliers, 3, 100000, "", "RANSAC inliers needed to restart after lost frames"},
      {"graph", "recovery_min_keypoints", &t.recovery_min_keypoints, 0, 100000, "", "fewer keypoints: a lost frame is re-acquired by the surface alone"},
      {"graph", "recovery_min_agreement", &t.recovery_min_agreement, 0.0, 1.0, "", "agreement such a re-acquisition needs"},
      {"graph", "gauss_newton_iterations", &t.gauss_newton.iterations, 0, 1000, "", "paper IV-D, original code: 7"},
      {"masks", "search_margin_px", &m.search_margin_px, 0, 10000, "px", "propagated: keypoints are searched this far around the last pose's silhouette"},
      {"masks", "growth_px", &m.growth_px, 0, 10000, "px", "propagated: the mask reaches this far beyond the rendered silhouette"},
      {"masks", "depth_agreement", &m.depth_agreement, 0.0, 1.0, "m", "propagated: observed vs rendered depth that seeds the mask"},
      {"masks", "depth_continuity", &m.depth_continuity, 0.0, 1.0, "m", "propagated: largest depth step between neighbouring mask pixels (up to 1 m; times z^2 beyond)"},
      {"masks", "hull_dilation_px", &m.hull_dilation_px, 0, 1000, "px", "propagated: slack of the first view's silhouette"},
      {"masks", "hull_depth_tolerance", &m.hull_depth_tolerance, 0.0, 1.0, "m", "propagated: slack in front of the first view's surface"},
      {"masks", "object_size_factor", &m.object_size_factor, 0.0, 100.0, "", "propagated, after lost: searched surfaces are at most this times the first view's extent"},
      {"masks", "min_area_fraction", &m.min_area_fraction, 0.0, 1.0, "", "propagated, after lost: and show this fraction of the first view's area"},
  };
}

/// Reads a YAML configuration (sections and keys of configParameters, plus the named choices of configChoices) over
/// the defaults. An unknown key, a value that is not a number, a non-integer for an integer
/// setting, or a value out of range is an InputError naming the file and the key.
inline Config loadConfig(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, std::filesystem::exists(path) ? "cannot open file" : "file not found");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  if (yaml.rfind("%YAML", 0) != 0) yaml = "%YAML:1.0\n---\n" + yaml;  // OpenCV needs the directive
  cv::FileStorage storage;
  try {
    storage.open(yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& error) {
    throw InputError(path, "not valid YAML (" + std::string(error.err) + ")");
  }
  Config config;
  auto parameters = configParameters(config);
  auto choices = configChoices(config);
  const cv::FileNode root = storage.root();
  if (!root.isMap() && !root.empty()) throw InputError(path, "expected sections of key: value pairs");
  for (const cv::FileNode section : root) {
    if (!section.isMap()) throw InputError(path, "'" + section.name() + "' must be a section of key: value pairs");
    for (const cv::FileNode node : section) {
      const std::string name = section.name() + "." + node.name();
      const auto choice = std::find_if(choices.begin(), choices.end(), [&](const ConfigChoice& c) {
        return section.name() == c.section && node.name() == c.key;
      });
      if (choice != choices.end()) {
        const std::string value = node.isString() ? std::string(node) : std::string();
        if (std::find(choice->names.begin(), choice->names.end(), value) == choice->names.end()) {
          std::string expected;
          for (const std::string& n : choice->names) expected += (expected.empty() ? "" : " | ") + n;
          throw InputError(path, name + " = '" + value + "': expected " + expected);
        }
        *choice->value = value;
        continue;
      }
      const auto found = std::find_if(parameters.begin(), parameters.end(), [&](const ConfigParameter& p) {
        return section.name() == p.section && node.name() == p.key;
      });
      if (found == parameters.end()) throw InputError(path, "unknown key '" + name + "'");
      if (!node.isInt() && !node.isReal()) throw InputError(path, name + " must be a number");
      const double value = node.isInt() ? double(int(node)) : double(node);
      const bool integral = !std::holds_alternative<float*>(found->value) && !std::holds_alternative<double*>(found->value);
      if (integral && (node.isReal() && value != std::floor(value)))
        throw InputError(path, name + " must be a whole number");
      if (!(value >= found->min && value <= found->max)) {
        std::ostringstream range;
        range << name << " = " << value << " is out of range [" << found->min << ", " << found->max << "]"
              << (*found->unit ? std::string(" ") + found->unit : "");
        throw InputError(path, range.str());
      }
      std::visit([&](auto* target) { *target = static_cast<std::remove_pointer_t<decltype(target)>>(value); },
                 found->value);
    }
  }
  // One set of detector-independent settings drives whichever detector is chosen.
  config.orb.max_keypoints = config.akaze.max_keypoints = config.sift.max_keypoints;
  config.orb.crop = config.akaze.crop = config.sift.crop;
  config.orb.matching = config.akaze.matching = config.sift.matching;
  return config;
}

/// The effective configuration as YAML that loadConfig reads back, each key under a comment with
/// its meaning and unit (OpenCV's YAML reader keeps a comment after a string value as part of it).
inline std::string printConfig(Config config) {
  std::ostringstream out;
  const auto printChoices = [&](const std::string& section) {
    for (const ConfigChoice& c : configChoices(config)) {
      if (section != c.section) continue;
      std::string names;
      for (const std::string& n : c.names) names += (names.empty() ? "" : " | ") + n;
      out << "  # " << c.meaning << " (" << names << ")\n  " << c.key << ": " << *c.value << "\n";
    }
  };
  std::vector<std::string> printed;
  std::string section;
  for (const ConfigParameter& p : configParameters(config)) {
    if (section != p.section) {
      section = p.section;
      printed.push_back(section);
      out << section << ":\n";
      printChoices(section);
    }
    out << "  # " << p.meaning << (*p.unit ? std::string(" [") + p.unit + "]" : "") << "\n  " << p.key << ": ";
    std::visit([&](auto* value) {
      using T = std::remove_pointer_t<decltype(value)>;
      if constexpr (std::is_floating_point_v<T>) {
        if (std::isinf(*value)) {
          out << ".inf";
        } else {
          char buffer[32];  // shortest text that reads back to the same value
          out << std::string_view(buffer, std::size_t(std::to_chars(buffer, buffer + sizeof(buffer), *value).ptr - buffer));
        }
      } else {
        out << *value;
      }
    }, p.value);
    out << "\n";
  }
  for (const ConfigChoice& c : configChoices(config)) {  // sections of choices alone
    if (std::find(printed.begin(), printed.end(), c.section) != printed.end()) continue;
    printed.push_back(c.section);
    out << c.section << ":\n";
    printChoices(c.section);
  }
  return out.str();
}

}  // namespace bundletrack::io
