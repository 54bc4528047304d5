#pragma once

#include <cmath>

namespace bundletrack {

/// The axial noise of a depth sensor: the standard deviation of one reading along its ray at
/// depth z (metres), for a depth camera with focal length f (pixels), and the depth grid its
/// disparity quantisation leaves. One formula covers the families as presets:
///   sigma(z) = base + quadratic (z - offset)^2 + z^2 subpixel / (f baseline)
/// - structured light (Kinect v1, Asus Xtion: the PrimeSense design): the first two terms, as
///   Nguyen, Izadi and Lovell measured them (3DIMPVT 2012: 1.2 mm + 1.9 mm/m^2 (z - 0.4 m)^2),
///   with disparity quantised in 1/8 pixel over a 7.5 cm baseline (Khoshelham and Elberink,
///   Sensors 2012);
/// - active stereo (RealSense D4xx): the third, the stereo depth RMS error z^2 subpixel /
///   (f baseline) with Intel's typical subpixel RMS of 0.08 px and the D435's 50 mm baseline.
struct DepthNoise {
  double base = 0.0;  ///< metres
  double quadratic = 0.0;  ///< metres per m^2 of (z - offset)^2
  double offset = 0.0;  ///< metres
  double subpixel = 0.0;  ///< pixels: RMS of the disparity (stereo term)
  double baseline = 0.075;  ///< metres: projector-camera or stereo baseline
  double disparity_step = 0.0;  ///< pixels: disparity quantisation (0: none)

  static DepthNoise structuredLight() { return {0.0012, 0.0019, 0.4, 0.0, 0.075, 0.125}; }
  static DepthNoise activeStereo() { return {0.0, 0.0, 0.0, 0.08, 0.05, 0.0}; }

  double sigma(double z, double focal_px) const {
    return base + quadratic * (z - offset) * (z - offset) + z * z * subpixel / (focal_px * baseline);
  }

  /// The depth spacing of neighbouring disparity levels at z (0 without quantisation).
  double quantisationStep(double z, double focal_px) const { return z * z * disparity_step / (focal_px * baseline); }

  /// z moved onto the nearest depth of the disparity grid (z itself without quantisation).
  double quantised(double z, double focal_px) const {
    if (disparity_step <= 0.0) return z;
    const double fb = focal_px * baseline;
    return fb / (std::round(fb / z / disparity_step) * disparity_step);
  }
};

}  // namespace bundletrack
