#include "bundletrack/cuda/matching.hpp"

#include <cstring>
#include <mutex>
#include <stdexcept>

#include "matching_device.hpp"

namespace bundletrack::cuda {

struct DescriptorMatcher::Workspace {
  std::mutex mutex;  // one search at a time uses the device buffers
  detail::MatchBuffers* buffers = detail::createMatchBuffers();
  ~Workspace() { detail::destroyMatchBuffers(buffers); }
};

DescriptorMatcher::DescriptorMatcher() : workspace_(std::make_shared<Workspace>()) {}

namespace {

/// CV_8U rows packed into zero-padded 32-bit words (the padding XORs to zero).
std::vector<std::uint32_t> packWords(const cv::Mat& rows, int words) {
  std::vector<std::uint32_t> packed(std::size_t(rows.rows) * std::size_t(words), 0u);
  for (int r = 0; r < rows.rows; ++r) std::memcpy(packed.data() + std::size_t(r) * std::size_t(words), rows.ptr(r), std::size_t(rows.cols));
  return packed;
}

}  // namespace

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
    const auto q = packWords(query, words), t = packWords(train, words);
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
