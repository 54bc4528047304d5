#pragma once

// The paper's choices of every policy, composed into DefaultTracker. A tracker of your own
// composes bundletrack/tracker.hpp with the policy headers it needs.

#include <utility>

#include "bundletrack/energy.hpp"
#include "bundletrack/features/opencv_features.hpp"
#include "bundletrack/masks/given_masks.hpp"
#include "bundletrack/registration/ransac.hpp"
#include "bundletrack/residuals/dense_photometric.hpp"
#include "bundletrack/residuals/dense_point_to_plane.hpp"
#include "bundletrack/residuals/dense_silhouette.hpp"
#include "bundletrack/residuals/feature_point_to_point.hpp"
#include "bundletrack/robust/losses.hpp"
#include "bundletrack/solvers/pcg.hpp"
#include "bundletrack/tracker.hpp"
#include "bundletrack/tracking/coarse_tracker.hpp"
#include "bundletrack/verification/surface_agreement.hpp"

namespace bundletrack {

/// Paper eq. 1 with lambda_1 = lambda_2 = 1 and Huber losses (delta 5 mm), and the photometric
/// and silhouette terms beside them (beyond the paper, docs/DESIGN.md section 7).
/// Default-constructed, each term has its own default: the photometric term's Huber delta is in
/// intensity (DensePhotometric::kHuberDelta), the silhouette term's in pixels
/// (DenseSilhouette::kHuberDelta), the others' 5 mm.
template <typename Dense = DensePointToPlane>
struct EnergyWithDense : Energy<Term<FeaturePointToPoint, HuberLoss>, Term<Dense, HuberLoss>, Term<DensePhotometric, HuberLoss>,
                                Term<DenseSilhouette, HuberLoss>> {
  using Base = Energy<Term<FeaturePointToPoint, HuberLoss>, Term<Dense, HuberLoss>, Term<DensePhotometric, HuberLoss>,
                      Term<DenseSilhouette, HuberLoss>>;
  EnergyWithDense()
      : Base{{{}, {}, {{}, HuberLoss{DensePhotometric::kHuberDelta}, 1.0}, {{}, HuberLoss{DenseSilhouette::kHuberDelta}, 1.0}}} {}
  explicit EnergyWithDense(Base energy) : Base(std::move(energy)) {}
};
using DefaultEnergy = EnergyWithDense<>;

/// BundleTrack with OpenCV's SIFT for the paper's learned features and the given masks for its
/// video segmentation: Gauss-Newton with PCG, RANSAC, surface-agreement verification.
using DefaultTracker = Tracker<DefaultEnergy, PCG, SiftFeatures, GivenMasks, Ransac, SurfaceAgreement>;

/// The baseline the pose graph must beat: frame-to-frame SIFT and RANSAC (paper IV-B alone).
using DefaultCoarseTracker = CoarseTracker<SiftFeatures, Ransac>;

}  // namespace bundletrack
