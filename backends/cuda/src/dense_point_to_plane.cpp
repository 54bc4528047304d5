#include "bundletrack/cuda/dense_point_to_plane.hpp"

#include <cstdint>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "dense_host.hpp"

namespace bundletrack::cuda {

namespace {

/// Tells a surface grid from another: FNV-1a over the data pointer, the sizes and the first and
/// last surface points (a grid whose memory another took differs in its points).
std::uint64_t signature(const SurfaceGrid& k) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  const void* data = k.points.data;
  mix(&data, sizeof(data));
  const int sizes[5] = {k.points.rows, k.points.cols, k.origin.x, k.origin.y, int(k.cells.size())};
  mix(sizes, sizeof(sizes));
  const std::size_t n = k.cells.size(), ends = std::min<std::size_t>(n, 16);
  for (std::size_t i = 0; i < ends; ++i) mix(&k.point(k.cells[i]), sizeof(cv::Vec3f));
  for (std::size_t i = n - ends; i < n; ++i) mix(&k.point(k.cells[i]), sizeof(cv::Vec3f));
  return h;
}

}  // namespace

struct DensePointToPlane::Workspace {
  static constexpr std::size_t kCapacity = 64;  ///< keyframe grids kept on the device

  struct Entry {
    detail::DeviceGrid* grid;
    std::uint64_t last_use;
  };

  std::mutex mutex;  // one batch at a time touches the device state
  std::map<std::uint64_t, Entry> grids;  ///< by signature
  detail::DeviceBatch* batch = detail::createBatch();
  std::vector<detail::BatchPass> passes;
  std::vector<double> sums;
  std::uint64_t batch_clock = 0;  ///< counts batches; a grid used by the current one is not evicted

  ~Workspace() {
    for (auto& [id, entry] : grids) detail::releaseGrid(entry.grid);
    detail::releaseBatch(batch);
  }

  /// k on the device, uploaded when not there yet. Evicts the least recently used grid beyond
  /// kCapacity, never one the current batch reads (the cache then holds more for a while).
  const detail::DeviceGrid* grid(const SurfaceGrid& k) {
    const std::uint64_t sig = signature(k);
    auto found = grids.find(sig);
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
      found = grids.emplace(sig, Entry{detail::uploadGrid(points.ptr<float>(), normals.ptr<float>(), points.cols,
                                                          points.rows, cells.data(), int(cells.size())),
                                      0})
                  .first;
    }
    found->second.last_use = batch_clock;
    return found->second.grid;
  }
};

DensePointToPlane::DensePointToPlane() : workspace_(std::make_shared<Workspace>()) {}

void DensePointToPlane::lineariseAllWith(std::span<const Input> inputs, std::span<const GraphEdge> edges,
                                         std::span<const SE3d> poses, const LossParameters& loss, double weight,
                                         std::span<PairSystem> systems) const {
  if (systems.size() != inputs.size() || edges.size() != inputs.size())
    throw std::invalid_argument("cuda::DensePointToPlane::lineariseAll: " + std::to_string(inputs.size()) + " inputs, " +
                                std::to_string(edges.size()) + " edges and " + std::to_string(systems.size()) +
                                " systems");
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  ++w.batch_clock;
  // Passes 2e and 2e + 1 are edge e's directions i -> j and j -> i.
  w.passes.clear();
  for (std::size_t e = 0; e < inputs.size(); ++e) {
    const Input& in = inputs[e];
    const SE3d& T_i = poses[std::size_t(edges[e].i)];
    const SE3d& T_j = poses[std::size_t(edges[e].j)];
    const detail::DeviceGrid* grid_i = w.grid(in.i);
    const detail::DeviceGrid* grid_j = w.grid(in.j);
    const SurfaceGate widened = gate.widened(NoiseScale::between(in.i.noise_scale, in.j.noise_scale));
    const double weight_i = weight * bundletrack::DensePointToPlane::sampleWeight(in.i);
    const double weight_j = weight * bundletrack::DensePointToPlane::sampleWeight(in.j);
    w.passes.push_back({grid_i, grid_j, detail::directedPass(T_i, T_j, in.j, widened, loss, weight_i)});
    w.passes.push_back({grid_j, grid_i, detail::directedPass(T_j, T_i, in.i, widened, loss, weight_j)});
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
