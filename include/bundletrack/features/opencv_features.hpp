#pragma once

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <vector>

#include <opencv2/features2d.hpp>

#include "bundletrack/features/lift_keypoints.hpp"
#include "bundletrack/features/matching.hpp"
#include "bundletrack/features/object_crop.hpp"
#include "bundletrack/features/optical_flow.hpp"

namespace bundletrack {

/// Where and how keypoints are detected, shared by the OpenCV correspondence sources.
struct CropSettings {
  int crop_size = 400;  ///< pixels; side of the square object crop the detector runs on
  int mask_dilation = 3;  ///< pixels (full resolution); the detector sees this much around the mask
  int normal_radius = 3;  ///< pixels; window of the plane fit giving each keypoint's normal
  float normal_max_depth_jump = 0.02f;  ///< metres
};

/// The common body of the OpenCV correspondence sources: detect on the object crop, keep the
/// max_keypoints strongest, map them back to full resolution, lift them to 3-D.
class OpenCvFeatureSource {
 public:
  static constexpr bool kConcurrentCalls = true;  ///< match() and follow() keep no state (ConcurrentCalls)

  FrameFeatures detect(const RgbdFrame& frame) {
    if (frame.mask.empty() || cv::countNonZero(frame.mask) == 0) {
      FrameFeatures none;
      none.norm_type = norm_type_;
      return none;
    }
    const ObjectCrop crop = makeObjectCrop(frame.color, frame.mask, crop_.crop_size, crop_.mask_dilation);
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    detector_->detectAndCompute(crop.gray, crop.mask, keypoints, descriptors);
    std::vector<int> order(keypoints.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return keypoints[a].response > keypoints[b].response; });
    order.resize(std::min<std::size_t>(order.size(), std::size_t(max_keypoints_)));
    std::vector<cv::Point2f> pixels;
    cv::Mat strongest(int(order.size()), descriptors.cols, descriptors.type());
    int kept = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
      // Detection sees the dilated mask (descriptors need the object's outline), but a keypoint
      // off the object would lift onto the background: keep only those inside the mask itself.
      const cv::Point2f pixel = crop.toImage(keypoints[order[k]].pt);
      const int u = roundToPixel(pixel.x), v = roundToPixel(pixel.y);
      if (u < 0 || v < 0 || u >= frame.mask.cols || v >= frame.mask.rows || !frame.mask.at<uchar>(v, u)) continue;
      pixels.push_back(pixel);
      descriptors.row(order[k]).copyTo(strongest.row(kept++));
    }
    strongest.resize(kept);
    return liftKeypoints(frame, pixels, strongest, norm_type_, crop_.normal_radius, crop_.normal_max_depth_jump);
  }

  std::vector<FeatureMatch> match(const FrameFeatures& first, const FrameFeatures& second,
                                  const std::optional<MatchGate>& gate = std::nullopt) const {
    return matchFeatures(first, second, matching_, gate);
  }

  /// The keypoints of the frame before (`last`, on its grey image and object mask) found in
  /// `frame` (grey image `gray`) by optical flow, lifted as detected ones are (followFeatures).
  FollowedFeatures follow(const cv::Mat& last_gray, const cv::Mat& last_mask, const FrameFeatures& last,
                          const RgbdFrame& frame, const cv::Mat& gray) const {
    return followFeatures(last_gray, last_mask, last, frame, gray, flow_, crop_.normal_radius, crop_.normal_max_depth_jump);
  }

 protected:
  OpenCvFeatureSource(cv::Ptr<cv::Feature2D> detector, int norm_type, int max_keypoints, CropSettings crop,
                      MatchSettings matching, FlowSettings flow)
      : detector_(std::move(detector)), norm_type_(norm_type), max_keypoints_(max_keypoints), crop_(crop),
        matching_(matching), flow_(flow) {}

 private:
  cv::Ptr<cv::Feature2D> detector_;
  int norm_type_;
  int max_keypoints_;
  CropSettings crop_;
  MatchSettings matching_;
  FlowSettings flow_;
};

struct SiftSettings {
  int max_keypoints = 500;
  double contrast_threshold = 0.01;
  double edge_threshold = 10.0;
  double sigma = 1.6;
  int octave_layers = 3;
  CropSettings crop;
  MatchSettings matching;
  FlowSettings flow;
};

/// SIFT, the default source: 500 keypoints, contrast threshold 0.01 as in the original
/// configuration (OpenCV's default 0.04 finds ~4x fewer on small objects).
class SiftFeatures : public OpenCvFeatureSource {
 public:
  using Settings = SiftSettings;
  SiftFeatures() : SiftFeatures(Settings{}) {}
  explicit SiftFeatures(const Settings& s)
      : OpenCvFeatureSource(cv::SIFT::create(s.max_keypoints, s.octave_layers, s.contrast_threshold, s.edge_threshold,
                                             s.sigma),
                            cv::NORM_L2, s.max_keypoints, s.crop, s.matching, s.flow) {}
};

struct OrbSettings {
  int max_keypoints = 500;
  float scale_factor = 1.2f;
  int levels = 8;
  int fast_threshold = 10;  ///< lower than OpenCV's 20: object crops are small and often low-contrast
  CropSettings crop;
  MatchSettings matching;
  FlowSettings flow;
};

/// ORB: binary descriptors, cheaper than SIFT, weaker under scale change.
class OrbFeatures : public OpenCvFeatureSource {
 public:
  using Settings = OrbSettings;
  OrbFeatures() : OrbFeatures(Settings{}) {}
  explicit OrbFeatures(const Settings& s)
      : OpenCvFeatureSource(cv::ORB::create(s.max_keypoints, s.scale_factor, s.levels, 31, 0, 2, cv::ORB::HARRIS_SCORE,
                                            31, s.fast_threshold),
                            cv::NORM_HAMMING, s.max_keypoints, s.crop, s.matching, s.flow) {}
};

struct AkazeSettings {
  int max_keypoints = 500;
  float threshold = 0.0005f;  ///< detector response threshold (OpenCV default 0.001)
  CropSettings crop;
  MatchSettings matching;
  FlowSettings flow;
};

/// AKAZE: nonlinear scale space with binary (MLDB) descriptors.
class AkazeFeatures : public OpenCvFeatureSource {
 public:
  using Settings = AkazeSettings;
  AkazeFeatures() : AkazeFeatures(Settings{}) {}
  explicit AkazeFeatures(const Settings& s)
      : OpenCvFeatureSource(cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, s.threshold), cv::NORM_HAMMING,
                            s.max_keypoints, s.crop, s.matching, s.flow) {}
};

}  // namespace bundletrack
