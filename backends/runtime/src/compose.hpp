#pragma once

// What every tracker of makeTracker is built from: the policies of a Config.

#include <memory>
#include <utility>

#include "bundletrack/config/config.hpp"
#include "bundletrack/default_tracker.hpp"
#include "bundletrack/tracking/any_tracker.hpp"

namespace bundletrack::runtime {

/// The detector `config.features` names with the settings every detector shares. SiftFeatures,
/// OrbFeatures and AkazeFeatures differ only in how they build their cv::Feature2D, so one
/// OpenCvFeatureSource type serves the run-time choice.
inline OpenCvFeatureSource featureSource(const Config& config) {
  if (config.features == "orb") {
    OrbSettings orb = config.orb;
    orb.max_keypoints = config.sift.max_keypoints, orb.crop = config.sift.crop, orb.matching = config.sift.matching;
    return OrbFeatures(orb);
  }
  if (config.features == "akaze") {
    AkazeSettings akaze = config.akaze;
    akaze.max_keypoints = config.sift.max_keypoints, akaze.crop = config.sift.crop, akaze.matching = config.sift.matching;
    return AkazeFeatures(akaze);
  }
  return SiftFeatures(config.sift);
}

/// Given masks drop their background over the same depth steps as propagated masks grow.
inline GivenMaskSettings givenMaskSettings(const Config& config) {
  return {config.drop_mask_background, config.propagated_masks.depth_continuity};
}

inline RansacSettings ransacSettings(const Config& config) {
  RansacSettings settings = config.ransac;
  settings.execution = config.execution;
  return settings;
}

/// The default energy (paper eq. 1, the photometric and silhouette terms) with a dense term of type Dense.
template <typename Dense>
EnergyWithDense<Dense> energy(const Config& config, Dense dense) {
  DensePhotometric photometric = config.photometric;
  photometric.gate = config.dense.gate;  // the dense term's association
  return EnergyWithDense<Dense>(
      {{Term<FeaturePointToPoint, HuberLoss>{{}, config.feature_loss, 1.0}, Term<Dense, HuberLoss>{std::move(dense), config.dense_loss, 1.0},
        Term<DensePhotometric, HuberLoss>{photometric, config.photometric_loss, config.photometric_weight},
        Term<DenseSilhouette, HuberLoss>{config.silhouette, config.silhouette_loss, config.silhouette_weight}},
       config.execution});
}

/// The full CPU tracker with the given mask source.
template <typename Masks>
std::unique_ptr<AnyTracker> cpuTracker(const Config& config, const PinholeCameraf& camera, Masks masks) {
  using CpuTracker = Tracker<DefaultEnergy, PCG, OpenCvFeatureSource, Masks, Ransac, SurfaceAgreement>;
  return eraseTracker(CpuTracker(camera, config.tracking, energy(config, config.dense), config.pcg, featureSource(config),
                                 std::move(masks), Ransac(ransacSettings(config)), SurfaceAgreement(config.verification)));
}

/// The full tracker with the GPU policies (gpu_trackers.cpp, where the CUDA backend is built).
std::unique_ptr<AnyTracker> gpuTracker(const Config& config, const PinholeCameraf& camera);

}  // namespace bundletrack::runtime
