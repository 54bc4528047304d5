#pragma once

#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bundletrack/core/disc_dilation.hpp"
#include "bundletrack/core/error.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/silhouette_image.hpp"
#include "bundletrack/core/surface_grid.hpp"
#include "bundletrack/masks/colour_likelihood.hpp"
#include "bundletrack/masks/depth_segments.hpp"
#include "bundletrack/masks/first_view_hull.hpp"
#include "bundletrack/masks/mask_source.hpp"
#include "bundletrack/masks/support_plane.hpp"

namespace bundletrack {

struct PropagatedMaskSettings {
  /// Keypoints are searched this far around the object's silhouette at the last pose: hand-held
  /// motion of 1 m/s at 30 Hz and 0.6 m moves the object ~30 px at f = 525 px.
  int search_margin_px = 40;
  /// The mask may reach this far beyond the rendered silhouette, where surface not seen before
  /// comes into view.
  int growth_px = 8;
  /// Observed depth within this of the rendered object depth seeds the mask: a few mm of coarse
  /// pose error plus 3 sigma of Kinect noise at 1.5 m (5 mm) plus grazing-angle spread. Like the
  /// two depth tolerances below, widened by the frame's NoiseScale at the pixel's depth.
  float depth_agreement = 0.02f;
  /// Neighbouring pixels of one surface differ by less than this in depth: 1 px is ~2 mm at 1 m, a
  /// 60 degree slant triples that, and objects stand out from their background by more.
  float depth_continuity = 0.01f;
  int hull_dilation_px = 5;  ///< pose and depth/colour registration error (1-3 px) of the first view
  float hull_depth_tolerance = 0.015f;  ///< metres in front of the first view's surface still inside
  /// After the object was lost, keypoints are searched on surfaces of about its size: at most this
  /// many times its first view's extent (a view from another side can be larger than the first) ...
  float object_size_factor = 2.0f;
  /// ... showing at least this fraction of the first view's pixel area scaled to their depth (a
  /// partly hidden or edge-on view shows less; depth dropouts cut the background into crumbs).
  float min_area_fraction = 0.25f;
  /// The mask stays off the surface the object rested on or leaned against in the first frame
  /// (SupportPlane; found there if there is one): within depth_continuity of that plane, widened
  /// by the noise, where depth cannot tell the object's foot from the support, a pixel joins only
  /// if its colour is more frequent on the first mask than around it (ColourLikelihood), or,
  /// where colour does not tell them apart in the first frame, only as a seed (agreeing with the
  /// rendered object: the mask does not grow there).
  bool stop_at_support = true;
};

/// Object masks from the first one alone (replacing the paper's video segmentation network): the
/// object surfaces seen so far are rendered under the coarse pose; pixels whose depth agrees seed
/// the mask, which then grows over depth-continuous pixels up to growth_px beyond the rendered
/// silhouette, never leaving the first view's hull (FirstViewHull) nor taking in the surface the
/// object rested on there (SupportPlane: the floor at a chair's legs, the table at a mug's foot,
/// told apart by colour within the plane's noise). A mask that comes out empty
/// means the object is not where the pose says: the tracker reports the frame lost.
/// Where the object stands out from what lies behind it, the mask's outline is that depth edge,
/// the data's and not the pose's, so the silhouette term reads it (kOutline); it holds only pixels
/// with depth, so one off it without a reading may still be the object's; elsewhere
/// the mask ends where the growth or the hull stops it, on a surface continuous with the object,
/// and there the term counts nothing: it weighs a point outside a mask only where that frame saw
/// past it (DenseSilhouette). Without it a textureless chair 3 m away slid along its seat and
/// back by up to 5.6 cm (docs/DESIGN.md, "Whose masks").
class PropagatedMasks {
 public:
  using Settings = PropagatedMaskSettings;
  static constexpr MaskOutline kOutline = MaskOutline::where_depth_read;
  /// Colour tells the object from its support where at least this share of the first mask and at
  /// most the rest of its ring look like the object (a two-class rule right on 80 % of each).
  static constexpr double kColourSeparates = 0.8;

  explicit PropagatedMasks(Settings settings = {}) : settings_(settings) {}

  /// The frame's mask as given: only the first frame's is read.
  cv::Mat frameMask(const RgbdFrame& frame) const { return frame.mask; }

  cv::Mat start(const RgbdFrame& first, const PinholeCameraf& camera, const SE3d& T_cam_obj, int grid_step) {
    if (first.mask.empty() || cv::countNonZero(first.mask) == 0)
      throw InputError("frame " + first.name, "propagated masks need a non-empty mask of the first frame");
    camera_ = camera;
    grid_step_ = grid_step;
    hull_ = FirstViewHull(first, camera, T_cam_obj, settings_.hull_dilation_px, settings_.hull_depth_tolerance);
    support_.reset();
    const cv::Mat ring = ringAround(first.mask, settings_.hull_dilation_px);
    if (settings_.stop_at_support) support_ = findSupportPlane(first, T_cam_obj, ring, settings_.depth_continuity);
    colour_decides_ = false;
    if (support_) {
      // Colour decides only where it tells the first mask from its ring: most of the object looks
      // like itself and most of the ring does not (a white mug on a white table: neither).
      colour_ = ColourLikelihood(first.color, first.mask, ring);
      colour_decides_ = colour_.objectLikeShare(first.color, first.mask) >= kColourSeparates &&
                        colour_.objectLikeShare(first.color, ring) <= 1.0 - kColourSeparates;
    }
    const cv::Mat seen = first.mask & (first.depth > 0.0f);
    first_area_ = cv::countNonZero(seen);
    if (first_area_ == 0)
      throw InputError("frame " + first.name, "no valid depth under the first mask: nothing to propagate it from");
    first_depth_ = float(cv::mean(first.depth, seen)[0]);
    started_ = true;
    return first.mask;
  }

  /// Without a guess (the object was lost) the whole image; else the box of the silhouette at the
  /// guess grown by the search margin (the keypoints' region) and the mask's growth (the coarse
  /// pose found there moves the silhouette at most that far).
  cv::Rect regionOfInterest(cv::Size image, const cv::Mat&, const ObservedObject& object,
                            const std::optional<SE3d>& T_guess) const {
    const cv::Rect whole({0, 0}, image);
    if (!started_ || !T_guess) return whole;
    const cv::Rect cells = cv::boundingRect(renderDepth(object.surfaces(*T_guess), *T_guess, gridSize(image)) > 0.0f);
    if (cells.area() == 0) return whole;
    const cv::Rect pixels(cells.x * grid_step_, cells.y * grid_step_, cells.width * grid_step_, cells.height * grid_step_);
    return grownWithin(pixels, settings_.search_margin_px + settings_.growth_px + grid_step_, image);
  }

  cv::Mat searchRegion(const RgbdFrame& frame, const ObservedObject& object, const std::optional<SE3d>& T_guess) const {
    requireStarted(frame);
    if (!T_guess) return objectSizedSurfaces(frame);
    cv::Mat silhouette = dilatedByDisc(renderDepth(object.surfaces(*T_guess), *T_guess, gridSize(frame.depth.size())) > 0.0f,
                                       (settings_.search_margin_px + grid_step_ - 1) / grid_step_);
    cv::resize(silhouette, silhouette, frame.depth.size(), 0.0, 0.0, cv::INTER_NEAREST);
    return silhouette & (frame.depth > 0.0f);
  }

  cv::Mat mask(const RgbdFrame& frame, const ObservedObject& object, const SE3d& T_cam_obj) const {
    requireStarted(frame);
    cv::Mat rendered;
    cv::resize(renderDepth(object.surfaces(T_cam_obj), T_cam_obj, gridSize(frame.depth.size())), rendered, frame.depth.size(), 0.0, 0.0, cv::INTER_NEAREST);
    const cv::Mat region = dilatedByDisc(rendered > 0.0f, settings_.growth_px);
    const cv::Rect box = cv::boundingRect(region);

    // Candidates: valid depth near the silhouette, inside the hull; seeds: those that agree.
    enum : uchar { kNone = 0, kCandidate = 1, kObject = 255 };
    cv::Mat label(frame.depth.size(), CV_8UC1, cv::Scalar(kNone));
    const SE3d T_obj_cam = T_cam_obj.inverse();
    std::vector<cv::Point> frontier;
    for (int v = box.y; v < box.y + box.height; ++v) {
      for (int u = box.x; u < box.x + box.width; ++u) {
        const float z = frame.depth.at<float>(v, u);
        if (!region.at<uchar>(v, u) || z <= 0.0f) continue;
        const cv::Vec3f& p = frame.points.at<cv::Vec3f>(v, u);
        const Eigen::Vector3d p_obj = T_obj_cam * Eigen::Vector3d(p[0], p[1], p[2]);
        if (!hull_.contains(p_obj)) continue;
        const float expected = rendered.at<float>(v, u);
        const bool agrees = expected > 0.0f && std::abs(z - expected) <= frame.noise.widen(settings_.depth_agreement, z);
        // Within the support plane's noise: the object's colour, where it tells, else only seeds.
        if (support_ && support_->distance(p_obj) <= frame.noise.widen(settings_.depth_continuity, z) &&
            (colour_decides_ ? !colour_.objectLike(frame.color.at<cv::Vec3b>(v, u)) : !agrees))
          continue;
        label.at<uchar>(v, u) = agrees ? kObject : kCandidate;
        if (agrees) frontier.emplace_back(u, v);
      }
    }
    // Grow over depth-continuous candidates (candidates lie inside the box).
    growOverContinuousDepth(
        frame.depth, settings_.depth_continuity, frame.noise, frontier,
        [&](const cv::Point& q) {
          if (label.at<uchar>(q) != kCandidate) return false;
          label.at<uchar>(q) = kObject;
          return true;
        },
        [](const cv::Point&) {});
    return label == kObject;
  }

 private:
  void requireStarted(const RgbdFrame& frame) const {
    if (!started_) throw InputError("frame " + frame.name, "propagated masks used before start() with a first mask");
  }

  /// Where the object may be when its pose is unknown: the depth-continuous surfaces of about its
  /// size (walls, tables and whatever holds the object are larger, crumbs of background smaller);
  /// the whole valid depth when there is none.
  cv::Mat objectSizedSurfaces(const RgbdFrame& frame) const {
    cv::Mat labels;
    const std::vector<DepthSegment> segments = segmentDepth(frame.depth, frame.points, settings_.depth_continuity, frame.noise, labels);
    std::vector<uchar> keep(segments.size());
    bool any = false;
    for (std::size_t k = 0; k < segments.size(); ++k) {
      const float z = 0.5f * (segments[k].low.z() + segments[k].high.z());
      const float expected_area = float(first_area_) * (first_depth_ * first_depth_) / (z * z);
      keep[k] = float(segments[k].pixels) >= settings_.min_area_fraction * expected_area &&
                segments[k].diagonal() <= settings_.object_size_factor * hull_.extent();
      any = any || keep[k];
    }
    if (!any) return frame.depth > 0.0f;
    cv::Mat region(frame.depth.size(), CV_8UC1);
    for (int v = 0; v < region.rows; ++v)
      for (int u = 0; u < region.cols; ++u) {
        const int id = labels.at<int>(v, u);
        region.at<uchar>(v, u) = id >= 0 && keep[std::size_t(id)] ? 255 : 0;
      }
    return region;
  }

  cv::Size gridSize(cv::Size image) const {
    return {(image.width + grid_step_ - 1) / grid_step_, (image.height + grid_step_ - 1) / grid_step_};
  }

  /// Depth of the observed surfaces under T_cam_obj on the grid (z-buffer, one grid cell per
  /// point), with one-cell holes between neighbouring points closed; 0 where nothing lands.
  cv::Mat renderDepth(const std::vector<ObservedSurface>& object, const SE3d& T_cam_obj, cv::Size size) const {
    const PinholeCameraf grid = downsampledCamera(camera_, grid_step_);
    cv::Mat depth(size, CV_32FC1, cv::Scalar(0.0f));
    cv::Rect drawn;  // the box of the cells drawn
    for (const ObservedSurface& surface : object) {
      const Eigen::Matrix<float, 3, 4> T = (T_cam_obj * surface.T_cam_obj.inverse()).matrix().topRows<3>().cast<float>();
      for (int y = 0; y < surface.points.rows; ++y) {
        for (int x = 0; x < surface.points.cols; ++x) {
          const cv::Vec3f& p = surface.points.at<cv::Vec3f>(y, x);
          if (p[2] <= 0.0f) continue;
          const Eigen::Vector3f q = T.leftCols<3>() * Eigen::Vector3f(p[0], p[1], p[2]) + T.col(3);
          int u = 0, v = 0;
          if (!grid.pixelOf(q, u, v) || u < 0 || v < 0 || u >= size.width || v >= size.height) continue;
          float& d = depth.at<float>(v, u);
          if (d == 0.0f || q.z() < d) d = q.z();
          drawn |= cv::Rect(u, v, 1, 1);
        }
      }
    }
    if (drawn.empty()) return depth;
    cv::Mat closed = depth.clone();
    const cv::Rect holes = grownWithin(drawn, 1, size);  // beyond it no cell has a drawn neighbour
    for (int v = holes.y; v < holes.br().y; ++v) {
      for (int u = holes.x; u < holes.br().x; ++u) {
        if (depth.at<float>(v, u) > 0.0f) continue;
        float nearest = 0.0f;
        int neighbours = 0;
        for (int dv = -1; dv <= 1; ++dv) {
          for (int du = -1; du <= 1; ++du) {
            const int uu = u + du, vv = v + dv;
            if (uu < 0 || vv < 0 || uu >= size.width || vv >= size.height) continue;
            const float d = depth.at<float>(vv, uu);
            if (d <= 0.0f) continue;
            ++neighbours;
            nearest = nearest == 0.0f ? d : std::min(nearest, d);
          }
        }
        if (neighbours >= 3) closed.at<float>(v, u) = nearest;  // inside the surface, not along its rim
      }
    }
    return closed;
  }

  Settings settings_;
  PinholeCameraf camera_{};
  int grid_step_ = 1;
  FirstViewHull hull_;
  std::optional<SupportPlane> support_;  ///< what the object rested on in the first frame, if anything
  ColourLikelihood colour_;  ///< the first mask's colours against those around it, with a support plane
  bool colour_decides_ = false;  ///< the likelihood tells the first mask from its ring (kColourSeparates)
  int first_area_ = 0;  ///< pixels of the first mask with depth
  float first_depth_ = 0.0f;  ///< their mean depth
  bool started_ = false;
};

}  // namespace bundletrack
