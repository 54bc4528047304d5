#include "bundletrack/cuda/ransac.hpp"

#include <mutex>

#include "ransac_device.hpp"
#include "ransac_host.hpp"

namespace bundletrack::cuda {

struct InlierCounter::Workspace {
  std::mutex mutex;  // one problem at a time uses the device buffers
  detail::RansacBuffers* buffers = detail::createRansacBuffers();
  const MatchedPoints* prepared = nullptr;  ///< the problem whose pairs are on the device
  std::vector<float> staging;
  std::vector<unsigned char> valid;
  ~Workspace() { detail::destroyRansacBuffers(buffers); }
};

InlierCounter::InlierCounter() : workspace_(std::make_shared<Workspace>()) {}

void InlierCounter::prepare(const MatchedPoints& pairs) {
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  detail::packPairs(pairs, w.staging);
  detail::uploadPairs(*w.buffers, w.staging.data(), int(pairs.size()));
  w.prepared = &pairs;
}

void InlierCounter::count(const MatchedPoints& pairs, const std::vector<SE3f>& hypotheses, const std::vector<char>& valid,
                          const InlierGate& gate, std::vector<int>& counts) const {
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  if (w.prepared != &pairs) throw std::logic_error("cuda::InlierCounter::count() before prepare() of these pairs");
  detail::packHypotheses(hypotheses, w.staging);
  w.valid.resize(hypotheses.size());
  for (std::size_t h = 0; h < hypotheses.size(); ++h) w.valid[h] = valid[h] ? 1 : 0;
  counts.resize(hypotheses.size());
  detail::countInliers(*w.buffers, w.staging.data(), w.valid.data(), int(hypotheses.size()), gate.max_squared_distance,
                       gate.cos_max_angle, counts.data());
}

}  // namespace bundletrack::cuda
