#pragma once

#include <string>

#include "bundletrack/core/intensity_image.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/core/silhouette_image.hpp"
#include "bundletrack/core/surface_grid.hpp"
#include "bundletrack/features/frame_features.hpp"

namespace bundletrack {

/// What the pose graph keeps of a frame: its pose, its features (paper eq. 2), its surface on
/// the dense grid (paper eq. 3), its brightness around the object (the photometric term) and its
/// silhouette (the silhouette term).
struct Keyframe {
  int id = 0;  ///< frame index in the sequence
  std::string name;
  SE3d T_cam_obj;
  FrameFeatures features;
  SurfaceGrid surface;
  IntensityImage image;
  SilhouetteImage silhouette;
};

/// Pixels beyond the mask that a keyframe's silhouette image covers: how far outside the outline
/// a point can land and still be pulled back in (9 cm at 3 m with a 525 px focal length).
constexpr int kSilhouetteMargin = 16;

/// The keyframe of `frame` under `mask`, its surface sampled every `grid_step` pixels. With
/// `with_image` (an energy term reads it) its intensity image reaches two grid steps beyond the
/// mask, as far as a point associated with the surface (within one cell of it) can project, and
/// holds the intensity at the surface's cells. Unless `outline` is MaskOutline::none (no energy
/// term reads one, or the mask is not the object's outline) its silhouette image reaches
/// kSilhouetteMargin pixels and two grid steps beyond the mask.
inline Keyframe makeKeyframe(int id, const RgbdFrame& frame, const cv::Mat& mask, FrameFeatures features,
                             const SE3d& T_cam_obj, const PinholeCameraf& camera, int grid_step, bool with_image = true,
                             MaskOutline outline = MaskOutline::every_pixel) {
  Keyframe keyframe{id, frame.name, T_cam_obj, std::move(features), sampleSurface(frame, mask, camera, grid_step), {}, {}};
  if (with_image) {
    keyframe.image = makeIntensityImage(frame.color, mask, 2 * grid_step);
    keyframe.image.sampleCells(keyframe.surface);
  }
  keyframe.silhouette = makeSilhouetteImage(frame, mask, outline, grid_step, kSilhouetteMargin + 2 * grid_step);
  return keyframe;
}

}  // namespace bundletrack
