#include "bundletrack/cuda/dense_point_to_plane.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <mutex>
#include <numbers>
#include <vector>

#include "dense_device.hpp"

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

void rowMajor3x4(const SE3d& T, double out[12]) {
  const Eigen::Matrix4d M = T.matrix();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = M(r, c);
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
      std::vector<int> cells(k.surface.size());
      for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = k.surface[i].y * k.points.cols + k.surface[i].x;
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
    detail::DirectedPass p{};
    rowMajor3x4(T_t * T_s.inverse(), p.T_t_s);
    rowMajor3x4(T_s * T_t.inverse(), p.T_s_t);
    rowMajor3x4(T_s.inverse(), p.T_s_inv);
    rowMajor3x4(T_t.inverse(), p.T_t_inv);
    p.cos_max = std::cos(double(max_normal_angle_deg) * std::numbers::pi / 180.0);
    p.max_sq = double(max_distance) * double(max_distance);
    p.fx = in.grid_camera.fx, p.fy = in.grid_camera.fy, p.cx = in.grid_camera.cx, p.cy = in.grid_camera.cy;
    p.loss_kind = int(loss.kind);
    p.loss_parameter = loss.parameter;
    p.weight = weight;
    double JtWJ[36], JtWr[6], cost = 0.0;
    int count = 0;
    detail::accumulateDense(*w.sums, s, t, p, JtWJ, JtWr, &cost, &count);
    // J_i is J_s, or -J_s when s is the edge's second node: J^T J keeps its sign, J^T r flips.
    const Eigen::Matrix<double, 6, 1> b = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(JtWr);
    system.addRelativeSums(Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(JtWJ), swapped ? -b : b, cost,
                           count);
  };
  pass(grid_i, grid_j, in.T_i, in.T_j, false);
  pass(grid_j, grid_i, in.T_j, in.T_i, true);
  system.finish();
}

}  // namespace bundletrack::cuda
