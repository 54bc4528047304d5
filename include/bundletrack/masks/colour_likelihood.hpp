#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace bundletrack {

/// Which of two regions of one image a colour looks more like: a colour histogram of each (BGR,
/// 16 levels per channel) compared as frequencies, a colour neither region showed counting as the
/// object's. Tells an object's foot from the table it stands on where depth cannot: both lie
/// within the noise of the table's plane.
class ColourLikelihood {
 public:
  ColourLikelihood() = default;

  /// From the pixels of `color` (CV_8UC3) under `object` and under `background` (CV_8UC1 masks;
  /// a pixel under both counts for the object).
  ColourLikelihood(const cv::Mat& color, const cv::Mat& object, const cv::Mat& background)
      : object_(kBins, 0), background_(kBins, 0) {
    for (int v = 0; v < color.rows; ++v) {
      for (int u = 0; u < color.cols; ++u) {
        const std::size_t bin = binOf(color.at<cv::Vec3b>(v, u));
        if (object.at<uchar>(v, u)) ++object_[bin], ++object_total_;
        else if (background.at<uchar>(v, u)) ++background_[bin], ++background_total_;
      }
    }
  }

  /// The share of the pixels of `color` under `region` that look like the object (objectLike).
  double objectLikeShare(const cv::Mat& color, const cv::Mat& region) const {
    int like = 0, all = 0;
    for (int v = 0; v < color.rows; ++v) {
      for (int u = 0; u < color.cols; ++u) {
        if (!region.at<uchar>(v, u)) continue;
        ++all;
        like += objectLike(color.at<cv::Vec3b>(v, u));
      }
    }
    return all > 0 ? double(like) / all : 0.0;
  }

  /// Whether `c` is at least as frequent among the object's colours as among the background's
  /// (always, for a likelihood made from no pixels).
  bool objectLike(const cv::Vec3b& c) const {
    if (object_.empty()) return true;
    const std::size_t bin = binOf(c);
    return double(object_[bin]) * double(background_total_) >= double(background_[bin]) * double(object_total_);
  }

 private:
  static constexpr std::size_t kLevels = 16, kBins = kLevels * kLevels * kLevels;
  static std::size_t binOf(const cv::Vec3b& c) {
    return (std::size_t(c[0]) * kLevels / 256 * kLevels + std::size_t(c[1]) * kLevels / 256) * kLevels +
           std::size_t(c[2]) * kLevels / 256;
  }

  std::vector<int> object_, background_;
  long long object_total_ = 0, background_total_ = 0;
};

}  // namespace bundletrack
