#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/angles.hpp"
#include "bundletrack/core/bilinear.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/pixel.hpp"
#include "bundletrack/core/rgbd_frame.hpp"

namespace bundletrack {

/// A frame's silhouette of the object, as the silhouette term reads it: the signed distance to
/// the mask's outline (pixels, positive outside, zero on the outline half a pixel beyond the
/// outermost mask pixels) and its derivatives along u and v; what the frame saw there, which tells
/// a point that the object hides from an occluder in front of it; and the frame's own object
/// points, every `step` pixels of the mask that have depth and are not behind a depth edge within
/// it (with or without a normal: the outermost ones are what the outline constrains), in the
/// camera frame.
struct SilhouetteImage {
  cv::Mat samples;  ///< CV_32FC3, box.size(): signed distance and its derivatives along u and v
  /// CV_32FC1, box.size(): what the frame saw at each pixel (metres): its reading; without one 0
  /// (unknown: a dropout, a shadow, the rim that the sensor and the depth filter's erosion take off
  /// a surface, an occluder that returns no light), except off a MaskOutline::every_pixel mask
  /// where no pixel off the mask within kSilhouetteEdgeRadius has a reading either, within the
  /// depth camera's view and the preprocessed region: infinity, nothing within the sensor's range
  /// (a far background), past every point.
  cv::Mat depth;
  cv::Rect box;  ///< of the full image: the mask's bounding box grown by the margin
  std::vector<cv::Vec3f> points;  ///< camera frame

  bool empty() const { return samples.empty(); }

  /// Bilinear signed distance and derivatives at full-resolution pixel (u, v); false outside the box.
  bool sample(double u, double v, double& distance, double& du, double& dv) const {
    return sampleBilinear(samples, box, {}, u, v, distance, du, dv);
  }

  /// Whether (u, v) lies deep inside the outline, a cheap test before sample(): its nearest pixel
  /// is more than 2.5 px from every pixel off the mask (signed distance below -2), so the four
  /// pixels a bilinear sample reads, within sqrt(2) of it, are all on the mask and the sampled
  /// distance is negative.
  bool deepInside(double u, double v) const {
    const int x = roundToPixel(u) - box.x, y = roundToPixel(v) - box.y;
    return x >= 0 && y >= 0 && x < box.width && y < box.height && samples.at<cv::Vec3f>(y, x)[0] < -2.0f;
  }

  /// What the frame saw at full-resolution pixel (u, v) (`depth`; 0: unknown, or outside the box).
  float depthAt(int u, int v) const {
    const int x = u - box.x, y = v - box.y;
    return x >= 0 && y >= 0 && x < box.width && y < box.height ? depth.at<float>(y, x) : 0.0f;
  }
};

/// What a frame's mask says of the object's outline, for its silhouette image (a mask source's
/// kOutline; without one it makes none).
enum class MaskOutline {
  none,  ///< the mask is not the object's outline (a search region): no silhouette image
  /// The outline where depth was read: a pixel off the mask without a reading may be the object's
  /// (a mask grown over depth-continuous pixels, PropagatedMasks, never holds one).
  where_depth_read,
  /// The outline at every pixel, read or not: a segmentation of the colour image (GivenMasks); a
  /// pixel off the mask is not the object's, and where neither it nor any pixel off the mask
  /// nearby has a reading the frame saw past every point there.
  every_pixel,
};

/// A mask that bleeds over the object's outline reads what lies behind it there. Its points are the
/// object's only where they lie no farther behind the nearest reading on the mask within this many
/// pixels than three standard deviations of two readings' difference plus the rise of a surface
/// at kSilhouetteEdgeSlopeDeg over that distance (a 4 px band of background, the widest a mask's
/// dilation or shift left in the stress tests, is then left out).
constexpr int kSilhouetteEdgeRadius = 4;
constexpr double kSilhouetteEdgeSlopeDeg = 75.0;

/// The silhouette image of `frame` under `mask`, an outline of kind `outline`, over the mask's
/// bounding box grown by `margin` pixels, its points every `step` pixels (empty without a mask
/// pixel, or for MaskOutline::none). Distances: exact Euclidean (cv::DIST_MASK_PRECISE) from the
/// pixel centres; derivatives: the 3x3 Sobel operator over 8.
inline SilhouetteImage makeSilhouetteImage(const RgbdFrame& frame, const cv::Mat& mask, MaskOutline outline, int step,
                                           int margin) {
  SilhouetteImage image;
  if (mask.empty() || outline == MaskOutline::none) return image;
  const cv::Rect object = cv::boundingRect(mask);
  if (object.area() == 0) return image;
  image.box = cv::Rect(object.x - margin, object.y - margin, object.width + 2 * margin, object.height + 2 * margin) &
              cv::Rect({0, 0}, mask.size());
  const cv::Mat inside = mask(image.box) != 0;
  cv::Mat outside_distance, inside_distance;
  cv::distanceTransform(~inside, outside_distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);  // to the nearest mask pixel
  cv::distanceTransform(inside, inside_distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);  // to the nearest pixel off it
  cv::Mat distance(inside.size(), CV_32FC1);
  for (int y = 0; y < inside.rows; ++y)
    for (int x = 0; x < inside.cols; ++x)
      distance.at<float>(y, x) = inside.at<uchar>(y, x) ? 0.5f - inside_distance.at<float>(y, x)
                                                        : outside_distance.at<float>(y, x) - 0.5f;
  cv::Mat d_u, d_v;
  cv::Sobel(distance, d_u, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(distance, d_v, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::merge(std::vector<cv::Mat>{distance, d_u, d_v}, image.samples);
  frame.depth(image.box).copyTo(image.depth);
  // Over the box and kSilhouetteEdgeRadius pixels beyond it: the nearest reading on the mask within
  // that radius of each pixel, and whether one off the mask lies within it.
  const cv::Rect around = grownWithin(image.box, kSilhouetteEdgeRadius, mask.size());
  const cv::Mat depth_around = frame.depth(around), on_mask = mask(around) != 0, readings = depth_around > 0.0f;
  const cv::Mat window = cv::Mat::ones(2 * kSilhouetteEdgeRadius + 1, 2 * kSilhouetteEdgeRadius + 1, CV_8UC1);
  const cv::Rect box_in_around = image.box - around.tl();
  cv::Mat nearest(around.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::max())), reading_off_mask_nearby;
  depth_around.copyTo(nearest, on_mask & readings);
  cv::erode(nearest, nearest, window);
  nearest = nearest(box_in_around);
  if (outline == MaskOutline::every_pixel) {
    cv::dilate(~on_mask & readings, reading_off_mask_nearby, window);
    reading_off_mask_nearby = reading_off_mask_nearby(box_in_around);
    const cv::Rect known = (frame.depth_view & preprocessedRegion(frame.region, mask.size())) - image.box.tl();
    const cv::Rect seen = known & cv::Rect({0, 0}, inside.size());
    const cv::Mat far = ~inside(seen) & ~reading_off_mask_nearby(seen);  // no reading here either
    image.depth(seen).setTo(std::numeric_limits<float>::infinity(), far);
  }
  const double rise_per_metre = kSilhouetteEdgeRadius * std::tan(radians(kSilhouetteEdgeSlopeDeg)) / frame.noise.focalLength();
  const int first_u = (object.x + step - 1) / step * step, first_v = (object.y + step - 1) / step * step;
  for (int v = first_v; v < object.y + object.height; v += step)
    for (int u = first_u; u < object.x + object.width; u += step) {
      const cv::Vec3f& p = frame.points.at<cv::Vec3f>(v, u);
      if (!mask.at<uchar>(v, u) || p[2] <= 0.0f) continue;
      const double z = nearest.at<float>(v - image.box.y, u - image.box.x);
      if (p[2] > z + 3.0 * std::sqrt(2.0) * frame.noise.spread(z) + rise_per_metre * z) continue;  // behind a depth edge
      image.points.push_back(p);
    }
  return image;
}

}  // namespace bundletrack
