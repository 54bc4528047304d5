#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "bundletrack/graph/keyframe_pool.hpp"

namespace bundletrack {

/// A point of the object's model, in the object frame.
struct ModelPoint {
  Eigen::Vector3f position;  ///< metres
  Eigen::Vector3f normal;  ///< unit, facing out of the surface as the keyframes saw it
  cv::Vec3b color;  ///< BGR (0 when the keyframes carry no colour)
};

struct ObjectModelSettings {
  /// Edge of the voxels the keyframes' points are averaged in (metres); 0: the keyframes' grid
  /// spacing at their median depth (step * z / fx), so the model is as dense as what was seen.
  float voxel_size = 0.0f;
  /// A voxel is kept when points of this many keyframes fall in it (at most the pool's size):
  /// mask pixels on the background land at different places of the object frame in each
  /// keyframe, the object's surface at the same place.
  int min_keyframes = 2;
};

/// The object's shape as a by-product of tracking: every keyframe's surface grid moved into the
/// object frame with the keyframe's (optimised) pose, averaged per voxel -- position, normal and
/// colour -- and voxels seen by fewer than min_keyframes keyframes dropped as outliers.
inline std::vector<ModelPoint> fuseObjectModel(const KeyframePool& pool, const ObjectModelSettings& settings = {}) {
  float voxel = settings.voxel_size;
  if (!(voxel > 0.0f)) {
    std::vector<float> spacings;
    for (std::size_t k = 0; k < pool.size(); ++k) {
      const SurfaceGrid& grid = pool[k].surface;
      std::vector<float> depths;
      for (const cv::Point& cell : grid.cells) depths.push_back(grid.point(cell)[2]);
      if (depths.empty()) continue;
      std::nth_element(depths.begin(), depths.begin() + std::ptrdiff_t(depths.size() / 2), depths.end());
      spacings.push_back(depths[depths.size() / 2] / grid.camera.fx);
    }
    if (spacings.empty()) return {};
    std::nth_element(spacings.begin(), spacings.begin() + std::ptrdiff_t(spacings.size() / 2), spacings.end());
    voxel = spacings[spacings.size() / 2];
  }
  struct Sum {
    Eigen::Vector3d position = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero(), color = Eigen::Vector3d::Zero();
    int points = 0, keyframes = 0;
    std::size_t last_keyframe = SIZE_MAX;
  };
  std::unordered_map<std::uint64_t, Sum> voxels;
  const auto key = [voxel](const Eigen::Vector3f& p) {
    const auto cell = [voxel](float x) { return std::uint64_t(std::int64_t(std::floor(x / voxel)) & 0x1fffff); };
    return cell(p.x()) | cell(p.y()) << 21 | cell(p.z()) << 42;  // 21 bits an axis: +-1 million voxels
  };
  for (std::size_t k = 0; k < pool.size(); ++k) {
    const SurfaceGrid& grid = pool[k].surface;
    const SE3f T_obj_cam = pool[k].T_cam_obj.inverse().cast<float>();
    for (std::size_t c = 0; c < grid.cells.size(); ++c) {
      const cv::Vec3f& p = grid.point(grid.cells[c]);
      const cv::Vec3f& n = grid.normal(grid.cells[c]);
      const Eigen::Vector3f position = T_obj_cam * Eigen::Vector3f(p[0], p[1], p[2]);
      Sum& sum = voxels[key(position)];
      sum.position += position.cast<double>();
      sum.normal += (T_obj_cam.rotation() * Eigen::Vector3f(n[0], n[1], n[2])).cast<double>();
      if (c < grid.colors.size()) sum.color += Eigen::Vector3d(grid.colors[c][0], grid.colors[c][1], grid.colors[c][2]);
      ++sum.points;
      if (sum.last_keyframe != k) sum.last_keyframe = k, ++sum.keyframes;
    }
  }
  const int needed = std::clamp(settings.min_keyframes, 1, std::max(1, int(pool.size())));
  std::vector<ModelPoint> model;
  for (const auto& [cell, sum] : voxels) {
    if (sum.keyframes < needed || sum.normal.norm() == 0.0) continue;
    const Eigen::Vector3d color = sum.color / double(sum.points);
    model.push_back({(sum.position / double(sum.points)).cast<float>(), sum.normal.normalized().cast<float>(),
                     cv::Vec3b(cv::saturate_cast<uchar>(color[0]), cv::saturate_cast<uchar>(color[1]),
                               cv::saturate_cast<uchar>(color[2]))});
  }
  // The map's order depends on the library's hashing: sort, so that a model is the same everywhere.
  std::sort(model.begin(), model.end(), [](const ModelPoint& a, const ModelPoint& b) {
    return std::lexicographical_compare(a.position.data(), a.position.data() + 3, b.position.data(), b.position.data() + 3);
  });
  return model;
}

}  // namespace bundletrack
