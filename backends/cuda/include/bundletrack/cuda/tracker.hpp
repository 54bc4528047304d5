#pragma once

#include "bundletrack/cuda/dense_point_to_plane.hpp"
#include "bundletrack/cuda/matching.hpp"
#include "bundletrack/cuda/pcg.hpp"
#include "bundletrack/cuda/ransac.hpp"
#include "bundletrack/default_tracker.hpp"

namespace bundletrack::cuda {

/// bundletrack::DefaultEnergy with the dense term on the GPU (the feature and photometric terms
/// stay on the CPU: a few hundred residuals per edge).
using DefaultEnergy = EnergyWithDense<DensePointToPlane>;

/// The tracker with every GPU policy of this backend: dense term, PCG, descriptor matching and
/// RANSAC on the device; the Detector finds keypoints on the CPU, the verification runs there.
template <CorrespondenceSource Detector = SiftFeatures, MaskSource Masks = GivenMasks>
using Tracker = bundletrack::Tracker<DefaultEnergy, PCG, GpuMatched<Detector>, Masks, Ransac, SurfaceAgreement>;

}  // namespace bundletrack::cuda
