#pragma once

#include <memory>

#include "bundletrack/config/config.hpp"
#include "bundletrack/core/camera.hpp"
#include "bundletrack/tracking/any_tracker.hpp"

namespace bundletrack {

/// The tracker a configuration describes, composed from the library's policies and compiled once
/// in bundletrack::runtime: the full tracker (given or propagated masks, on the CPU or with the
/// GPU policies of bundletrack::cuda) or the coarse one, with the detector, energy, solver,
/// RANSAC and verification settings of `config`. A combination that does not exist (the coarse
/// tracker with propagated masks or on the GPU), or a choice outside its names, is a
/// std::invalid_argument naming the keys; asking for the GPU without a CUDA backend in this build
/// or without a device is a std::runtime_error saying which.
std::unique_ptr<AnyTracker> makeTracker(const Config& config, const PinholeCameraf& camera);

}  // namespace bundletrack
