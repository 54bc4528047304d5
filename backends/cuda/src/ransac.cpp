#include "bundletrack/cuda/ransac.hpp"

#include <mutex>
#include <stdexcept>

#include "ransac_device.hpp"
#include "ransac_host.hpp"

namespace bundletrack::cuda {

struct TrialScorer::Workspace {
  std::mutex mutex;  // one problem at a time uses the device buffers
  detail::RansacBuffers* buffers = detail::createRansacBuffers();
  const MatchedPoints* prepared = nullptr;  ///< the problem whose pairs are on the device
  std::vector<float> staging;
  std::vector<double> fits;
  std::vector<unsigned char> valid;
  ~Workspace() { detail::destroyRansacBuffers(buffers); }
};

TrialScorer::TrialScorer() : workspace_(std::make_shared<Workspace>()) {}

void TrialScorer::prepare(const MatchedPoints& pairs) {
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  detail::packPairs(pairs, w.staging);
  detail::uploadPairs(*w.buffers, w.staging.data(), int(pairs.size()));
  w.prepared = &pairs;
}

void TrialScorer::score(const MatchedPoints& pairs, const RansacSettings& settings, const InlierGate& gate, int first,
                        int count, std::vector<SE3d>& fits, std::vector<char>& valid, std::vector<int>& scores) const {
  Workspace& w = *workspace_;
  const std::lock_guard lock(w.mutex);
  if (w.prepared != &pairs) throw std::logic_error("cuda::TrialScorer::score() before prepare() of these pairs");
  const detail::TrialParameters parameters{settings.seed, settings.min_sample_spread, gate.max_squared_distance,
                                           gate.cos_max_angle};
  w.fits.resize(12 * std::size_t(count));
  w.valid.resize(std::size_t(count));
  scores.resize(std::size_t(count));
  detail::scoreTrials(*w.buffers, parameters, first, count, w.fits.data(), w.valid.data(), scores.data());
  fits.resize(std::size_t(count));
  valid.resize(std::size_t(count));
  for (std::size_t b = 0; b < std::size_t(count); ++b) {
    valid[b] = w.valid[b] != 0;
    if (valid[b]) fits[b] = detail::poseOf(w.fits.data() + 12 * b);
  }
}

}  // namespace bundletrack::cuda
