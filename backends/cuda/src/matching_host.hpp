#pragma once

// What the host hands the matching kernel: binary descriptors as 32-bit words.

#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/core.hpp>

namespace bundletrack::cuda::detail {

/// CV_8U rows packed into zero-padded 32-bit words (the padding XORs to zero).
inline std::vector<std::uint32_t> packWords(const cv::Mat& rows, int words) {
  std::vector<std::uint32_t> packed(std::size_t(rows.rows) * std::size_t(words), 0u);
  for (int r = 0; r < rows.rows; ++r)
    std::memcpy(packed.data() + std::size_t(r) * std::size_t(words), rows.ptr(r), std::size_t(rows.cols));
  return packed;
}

}  // namespace bundletrack::cuda::detail
