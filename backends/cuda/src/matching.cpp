#include "bundletrack/cuda/matching.hpp"

#include <mutex>
#include <stdexcept>

#include "matching_device.hpp"
#include "matching_host.hpp"

namespace bundletrack::cuda {

struct DescriptorMatcher::Workspace {
  std::mutex mutex;  // one search at a time uses the device buffers
  detail::MatchBuffers* buffers = detail::createMatchBuffers();
  ~Workspace() { detail::destroyMatchBuffers(buffers); }
};

DescriptorMatcher::DescriptorMatcher() : workspace_(std::make_shared<Workspace>()) {}

std::vector<TwoNearest> DescriptorMatcher::twoNearest(const cv::Mat& query, const cv::Mat& train, int norm_type) const {
  if (query.cols != train.cols || query.type() != train.type())
    throw std::invalid_argument("GPU matcher: query and train descriptors differ in width or type");
  const int queries = query.rows, trains = train.rows;
  const std::lock_guard lock(workspace_->mutex);
  std::vector<int> index(static_cast<std::size_t>(queries));
  std::vector<float> best(static_cast<std::size_t>(queries)), second(static_cast<std::size_t>(queries));
  if (norm_type == cv::NORM_L2 && query.type() == CV_32F) {
    const cv::Mat q = query.isContinuous() ? query : query.clone(), t = train.isContinuous() ? train : train.clone();
    detail::twoNearestL2(*workspace_->buffers, q.ptr<float>(), queries, t.ptr<float>(), trains, query.cols, index.data(),
                         best.data(), second.data());
  } else if (norm_type == cv::NORM_HAMMING && query.type() == CV_8U) {
    const int words = (query.cols + 3) / 4;
    const auto q = detail::packWords(query, words), t = detail::packWords(train, words);
    detail::twoNearestHamming(*workspace_->buffers, q.data(), queries, t.data(), trains, words, index.data(), best.data(),
                              second.data());
  } else {
    throw std::invalid_argument("GPU matcher: expects CV_32F descriptors with NORM_L2 or CV_8U with NORM_HAMMING");
  }
  std::vector<TwoNearest> nearest(static_cast<std::size_t>(queries));
  for (std::size_t k = 0; k < nearest.size(); ++k) nearest[k] = {index[k], best[k], second[k]};
  return nearest;
}

}  // namespace bundletrack::cuda
