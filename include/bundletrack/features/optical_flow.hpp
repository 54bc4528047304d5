#pragma once

#include <algorithm>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/features/frame_features.hpp"
#include "bundletrack/features/lift_keypoints.hpp"

namespace bundletrack {

/// Pyramidal Lucas-Kanade (Bouguet's formulation, OpenCV's calcOpticalFlowPyrLK) that follows one
/// frame's keypoints into the next.
struct FlowSettings {
  int window = 21;  ///< px, side of the matched patch at each pyramid level
  int levels = 3;  ///< pyramid levels above full resolution: motions up to ~window * 2^levels / 2 px
  /// px: a followed point, followed back, must land this close to where it started (the
  /// forward-backward check of Kalal et al., ICPR 2010); SIFT places a keypoint within ~0.5 px.
  float max_round_trip_px = 0.5f;
};

/// Follows `last`'s keypoints (on `last_gray`, the grey image of the frame they were detected or
/// followed on, and `last_mask`, that frame's object mask) into `frame` (grey image `gray`) by pyramidal Lucas-Kanade
/// within the box around both the keypoints and `frame`'s mask (the region the object is searched
/// in), grown by the flow window. Only keypoints whose whole window lies on the object are
/// followed: a window that takes in background, which moves otherwise, drags the point along
/// (on a 10 cm mug 1-2 m away most of them would, and the mug's turn drifted by 2-3x). Kept:
/// points that pass the forward-backward check, land on `frame`'s mask and have a depth reading
/// and a normal there (liftKeypoints with `normal_radius` and `normal_max_depth_jump`, as the
/// detector lifts).
inline FollowedFeatures followFeatures(const cv::Mat& last_gray, const cv::Mat& last_mask, const FrameFeatures& last,
                                       const RgbdFrame& frame, const cv::Mat& gray, const FlowSettings& settings,
                                       int normal_radius, float normal_max_depth_jump) {
  FollowedFeatures followed;
  followed.features.norm_type = last.norm_type;
  const cv::Size size = frame.color.size();
  if (last.size() == 0 || frame.mask.empty() || last_gray.size() != size || last_mask.size() != size || gray.size() != size)
    return followed;
  const cv::Rect image({0, 0}, size);
  const int margin = settings.window;
  const cv::Rect around = (cv::boundingRect(last.pixels) | cv::boundingRect(frame.mask)) + cv::Size(2 * margin, 2 * margin) -
                          cv::Point(margin, margin);
  const cv::Rect box = around & image;
  if (box.empty()) return followed;
  cv::Mat inner;  // where a window centred lies on the object in the last frame (outside the image counts as off it)
  cv::erode(last_mask(box), inner, cv::getStructuringElement(cv::MORPH_RECT, {settings.window, settings.window}),
            {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  const cv::Mat before = last_gray(box), after = gray(box);
  const cv::Point2f offset(float(box.x), float(box.y));
  std::vector<cv::Point2f> start, forward, back;
  std::vector<int> start_from;
  for (std::size_t k = 0; k < last.size(); ++k) {
    const cv::Point2f p = last.pixels[k] - offset;
    const int u = roundToPixel(p.x), v = roundToPixel(p.y);
    if (u < 0 || v < 0 || u >= inner.cols || v >= inner.rows || !inner.at<uchar>(v, u)) continue;
    start.push_back(p);
    start_from.push_back(int(k));
  }
  followed.tried = int(start.size());
  if (start.empty()) return followed;
  std::vector<uchar> found_forward, found_back;
  std::vector<float> error;
  const cv::Size window(settings.window, settings.window);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  // Each image's pyramid (with its derivatives) serves both directions: built once, not twice.
  std::vector<cv::Mat> before_pyramid, after_pyramid;
  cv::buildOpticalFlowPyramid(before, before_pyramid, window, settings.levels, true);
  cv::buildOpticalFlowPyramid(after, after_pyramid, window, settings.levels, true);
  cv::calcOpticalFlowPyrLK(before_pyramid, after_pyramid, start, forward, found_forward, error, window, settings.levels, stop);
  cv::calcOpticalFlowPyrLK(after_pyramid, before_pyramid, forward, back, found_back, error, window, settings.levels, stop);
  std::vector<cv::Point2f> pixels;
  std::vector<int> followed_from;
  for (std::size_t k = 0; k < start.size(); ++k) {
    if (!found_forward[k] || !found_back[k]) continue;
    const cv::Point2f round_trip = back[k] - start[k];
    if (round_trip.dot(round_trip) > settings.max_round_trip_px * settings.max_round_trip_px) continue;
    const cv::Point2f pixel = forward[k] + offset;
    const int u = roundToPixel(pixel.x), v = roundToPixel(pixel.y);
    if (!image.contains({u, v}) || !frame.mask.at<uchar>(v, u)) continue;
    pixels.push_back(pixel);
    followed_from.push_back(start_from[k]);
  }
  cv::Mat descriptors(int(pixels.size()), last.descriptors.cols, last.descriptors.type());
  for (std::size_t i = 0; i < followed_from.size(); ++i)
    last.descriptors.row(followed_from[i]).copyTo(descriptors.row(int(i)));
  std::vector<int> lifted;
  followed.features = liftKeypoints(frame, pixels, descriptors, last.norm_type, normal_radius, normal_max_depth_jump, &lifted);
  for (std::size_t i = 0; i < lifted.size(); ++i) followed.matches.push_back({followed_from[std::size_t(lifted[i])], int(i)});
  return followed;
}

}  // namespace bundletrack
