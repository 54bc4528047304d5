#include "bundletrack/cuda/dense_point_to_plane.hpp"

#include <cstdint>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
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

  std::mutex mutex;  // one batch at a time touches the device state
  std::map<int, Entry> grids;
  detail::DeviceBatch* batch = detail::createBatch();
  std::vector<detail::BatchPass> passes;
  std::vector<double> sums;
  std::uint64_t batch_clock = 0;  ///< counts batches; a grid used by the current one is not evicted

  ~Workspace() {
    for (auto& [id, entry] : grids) detail::releaseGrid(entry.grid);
    detail::releaseBatch(batch);
  }

  /// k's grid on the device, uploaded when absent or changed. Evicts the least recently used grid
  /// beyond kCapacity, never one the current batch reads (the cache then holds more for a while).
  const detail::DeviceGrid* grid(const Keyframe& k) {
    const std::uint64_t sig = signature(k);
    auto found = grids.find(k.id);
    if (found != grids.end() && found->second.signature != sig) {
      if (found->second.last_use == batch_clock)
        throw std::logic_error("cuda::DensePointToPlane: two different grids with keyframe id " + std::to_string(k.id) +
                               " in one graph");
      detail::releaseGrid(found->second.grid);
      grids.erase(found);
      found = grids.end();
    }
    if (found == grids.end()) {
      if (grids.size() >= kCapacity) {
        auto oldest = grids.end();
        for (auto it = grids.begin(); it != grids.end(); ++it)
          if (it->second.last_use < batch_clock && (oldest == grids.end() || it->second.last_use < oldest->second.last_use))
            oldest = it;
        if (oldest != grids.end()) {
          detail::releaseGrid(oldest->second.grid);
          grids.erase(oldest);
        }
      }
      const cv::Mat points = k.points.isContinuous() ? k.points : k.points.clone();
      const cv::Mat normals = k.normals.isContinuous() ? k.normals : k.normals.clone();
      const std::vector<int> cells = detail::surfaceCells(k);
      found = grids.emplace(k.id, Entry{detail::uploadGrid(points.ptr<float>(), normals.ptr<float>(), points.cols,
                                                            points.rows, cells.data(), int(cells.size())),
                                        sig, 0})
                  .first;
    }
    found->second.last_use = batch_clock;
    return found->second.grid;
  }
};

DensePointToPlane::DensePointToPlane() : workspace_(std::make_shared<Workspace>()) {}

void DensePointToPlane::lineariseAllWith(std::span<const PairInput> inputs, const LossParameters& loss, double weight,
                                         std::span<PairSystem> systems) const {
  if (systems.size() != inputs.size())
    throw std::invalid_argument("cuda::DensePointToPlane::lineariseAll: " + std::to_string(inputs.size()) +
                                " edges but " + std::to_string(systems.size()) + " systems");
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  ++w.batch_clock;
  // Passes 2e and 2e + 1 are edge e's directions i -> j and j -> i.
  w.passes.clear();
  for (const PairInput& in : inputs) {
    const detail::DeviceGrid* grid_i = w.grid(in.i);
    const detail::DeviceGrid* grid_j = w.grid(in.j);
    w.passes.push_back({grid_i, grid_j,
                        detail::directedPass(in.T_i, in.T_j, in.grid_camera, max_distance, max_normal_angle_deg, loss,
                                             weight)});
    w.passes.push_back({grid_j, grid_i,
                        detail::directedPass(in.T_j, in.T_i, in.grid_camera, max_distance, max_normal_angle_deg, loss,
                                             weight)});
  }
  w.sums.resize(w.passes.size() * detail::kDenseSums);
  detail::accumulateDense(*w.batch, w.passes.data(), int(w.passes.size()), w.sums.data());
  for (std::size_t e = 0; e < inputs.size(); ++e) {
    detail::addPassSums(w.sums.data() + 2 * e * detail::kDenseSums, false, systems[e]);
    detail::addPassSums(w.sums.data() + (2 * e + 1) * detail::kDenseSums, true, systems[e]);
    systems[e].finish();
  }
}

}  // namespace bundletrack::cuda
