#include "bundletrack/cuda/dense_point_to_plane.hpp"

#include <cstdint>
#include <map>
#include <mutex>
#include <vector>

#include "dense_host.hpp"

namespace bundletrack::cuda {

namespace {

/// Tells a keyframe's grid from another that took its id or its memory: FNV-1a over the data
/// pointer, the sizes and the first and last surface points.
std::uint64_t signature(const Keyframe& k) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  const void* data = k.points.data;
  mix(&data, sizeof(data));
  const int sizes[3] = {k.points.rows, k.points.cols, int(k.surface.size())};
  mix(sizes, sizeof(sizes));
  const std::size_t n = k.surface.size(), ends = std::min<std::size_t>(n, 16);
  for (std::size_t i = 0; i < ends; ++i) mix(&k.points.at<cv::Vec3f>(k.surface[i]), sizeof(cv::Vec3f));
  for (std::size_t i = n - ends; i < n; ++i) mix(&k.points.at<cv::Vec3f>(k.surface[i]), sizeof(cv::Vec3f));
  return h;
}

}  // namespace

struct DensePointToPlane::Workspace {
  static constexpr std::size_t kCapacity = 64;  ///< keyframe grids kept on the device

  struct Entry {
    detail::DeviceGrid* grid;
    std::uint64_t signature;
    std::uint64_t last_use;
  };

  std::mutex mutex;  // edges linearise in parallel; device state is touched by one at a time
  std::map<int, Entry> grids;
  detail::DeviceSums* sums = detail::createSums();
  std::uint64_t clock = 0;

  ~Workspace() {
    for (auto& [id, entry] : grids) detail::releaseGrid(entry.grid);
    detail::releaseSums(sums);
  }

  const detail::DeviceGrid& grid(const Keyframe& k) {
    const std::uint64_t sig = signature(k);
    auto found = grids.find(k.id);
    if (found != grids.end() && found->second.signature != sig) {
      detail::releaseGrid(found->second.grid);
      grids.erase(found);
      found = grids.end();
    }
    if (found == grids.end()) {
      if (grids.size() >= kCapacity) {
        auto oldest = grids.begin();
        for (auto it = grids.begin(); it != grids.end(); ++it)
          if (it->second.last_use < oldest->second.last_use) oldest = it;
        detail::releaseGrid(oldest->second.grid);
        grids.erase(oldest);
      }
      const cv::Mat points = k.points.isContinuous() ? k.points : k.points.clone();
      const cv::Mat normals = k.normals.isContinuous() ? k.normals : k.normals.clone();
      const std::vector<int> cells = detail::surfaceCells(k);
      found = grids.emplace(k.id, Entry{detail::uploadGrid(points.ptr<float>(), normals.ptr<float>(), points.cols,
                                                            points.rows, cells.data(), int(cells.size())),
                                        sig, 0})
                  .first;
    }
    found->second.last_use = ++clock;
    return *found->second.grid;
  }
};

DensePointToPlane::DensePointToPlane() : workspace_(std::make_shared<Workspace>()) {}

void DensePointToPlane::lineariseWith(const PairInput& in, const LossParameters& loss, double weight,
                                      PairSystem& system) const {
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  const detail::DeviceGrid& grid_i = w.grid(in.i);
  const detail::DeviceGrid& grid_j = w.grid(in.j);
  const auto pass = [&](const detail::DeviceGrid& s, const detail::DeviceGrid& t, const SE3d& T_s, const SE3d& T_t,
                        bool swapped) {
    const detail::DirectedPass p = detail::directedPass(T_s, T_t, in.grid_camera, max_distance, max_normal_angle_deg,
                                                        loss, weight);
    double sums[detail::kDenseSums];
    detail::accumulateDense(*w.sums, s, t, p, sums);
    detail::addPassSums(sums, swapped, system);
  };
  pass(grid_i, grid_j, in.T_i, in.T_j, false);
  pass(grid_j, grid_i, in.T_j, in.T_i, true);
  system.finish();
}

}  // namespace bundletrack::cuda
