#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace bundletrack {

/// The axial noise of a depth sensor: the standard deviation of one reading along its ray at
/// depth z (metres), for a depth camera with focal length f (pixels), and the depth grid its
/// disparity quantisation leaves. One formula covers the families as presets:
///   sigma(z) = base + linear z + quadratic (z - offset)^2 + z^2 subpixel / (f baseline)
/// - structured light (Kinect v1, Asus Xtion: the PrimeSense design): base and quadratic terms as
///   Nguyen, Izadi and Lovell measured them (3DIMPVT 2012: 1.2 mm + 1.9 mm/m^2 (z - 0.4 m)^2),
///   with disparity quantised in 1/8 pixel over a 7.5 cm baseline (Khoshelham and Elberink,
///   Sensors 2012);
/// - active stereo (RealSense D4xx): the stereo depth RMS error z^2 subpixel / (f baseline) with
///   Intel's typical subpixel RMS of 0.08 px and the D435's 50 mm baseline;
/// - time of flight (Azure Kinect, NFOV unbinned): Microsoft specifies a random error of at most
///   17 mm over the 0.5-3.86 m range (confirmed by Toelgyessy et al., Sensors 2021). An AMCW phase
///   measurement is shot-noise limited (sigma ~ 1/sqrt(returned light), light ~ 1/z^2), so sigma
///   grows linearly with z: the preset reaches the specified bound at the end of the range,
///   17 mm / 3.86 m = 4.4 mm per metre. A worst case: a device measured better is set by hand.
struct DepthNoise {
  double base = 0.0;  ///< metres
  double linear = 0.0;  ///< metres per metre of depth
  double quadratic = 0.0;  ///< metres per m^2 of (z - offset)^2
  double offset = 0.0;  ///< metres
  double subpixel = 0.0;  ///< pixels: RMS of the disparity (stereo term)
  double baseline = 0.075;  ///< metres: projector-camera or stereo baseline
  double disparity_step = 0.0;  ///< pixels: disparity quantisation (0: none)
  /// Metres: the farthest depth the sensor's specification covers (0: unknown). Only the depth
  /// unit check reads it (io::checkDepthScale).
  double max_range = 0.0;

  bool operator==(const DepthNoise&) const = default;

  /// Ranges: Kinect v1 0.8-4 m (default mode), RealSense D435 up to 10 m, Azure Kinect NFOV
  /// (2x2 binned) 0.5-5.46 m.
  static DepthNoise structuredLight() { return {0.0012, 0.0, 0.0019, 0.4, 0.0, 0.075, 0.125, 4.0}; }
  static DepthNoise activeStereo() { return {0.0, 0.0, 0.0, 0.0, 0.08, 0.05, 0.0, 10.0}; }
  static DepthNoise timeOfFlight() { return {0.0, 0.017 / 3.86, 0.0, 0.0, 0.0, 0.075, 0.0, 5.46}; }

  double sigma(double z, double focal_px) const {
    return base + linear * z + quadratic * (z - offset) * (z - offset) + z * z * subpixel / (focal_px * baseline);
  }

  /// The depth spacing of neighbouring disparity levels at z (0 without quantisation).
  double quantisationStep(double z, double focal_px) const {
    return z * z * disparity_step / (focal_px * baseline);
  }

  /// The spread of one reading: the random noise and the rounding onto the disparity grid, whose
  /// error is uniform over one step (standard deviation step / sqrt(12)).
  double spread(double z, double focal_px) const {
    const double s = sigma(z, focal_px), q = quantisationStep(z, focal_px);
    return std::sqrt(s * s + q * q / 12.0);
  }

  /// z moved onto the nearest depth of the disparity grid (z itself without quantisation).
  double quantised(double z, double focal_px) const {
    if (disparity_step <= 0.0) return z;
    const double fb = focal_px * baseline;
    return fb / (std::round(fb / z / disparity_step) * disparity_step);
  }
};

/// How much noisier a sensor's readings are than those the fixed tolerances were set for.
/// Every depth or 3-D distance tolerance of the tracker (RANSAC's 5 mm, the 2 cm gates, the 1 cm
/// agreement, the depth filter's windows, the mask's flood limits) is the paper's or the original
/// code's value for Kinect-class data around 1 m; at depth z a sensor whose spread there is s times
/// the reference spread -- structured light at 1 m seen with a 525 px focal length, 2.1 mm --
/// widens each tolerance s times, and never narrows it (scale >= 1). A tolerance is then the same
/// number of standard deviations of the noise at any distance and from any sensor.
class NoiseScale {
 public:
  explicit NoiseScale(DepthNoise noise = DepthNoise::structuredLight(), double focal_px = 525.0)
      : noise_(noise), focal_px_(focal_px) {
    // The spread grows with depth beyond the quadratic term's vertex, where every preset's is
    // below the reference: bisect for the depth where it reaches the reference.
    double lo = std::max(0.0, noise_.offset), hi = 100.0;
    if (ratio(hi) <= 1.0) lo = hi;
    for (int i = 0; i < 60 && hi - lo > 1e-6; ++i) (ratio(0.5 * (lo + hi)) > 1.0 ? hi : lo) = 0.5 * (lo + hi);
    unit_depth_ = lo;
  }

  const DepthNoise& noise() const { return noise_; }
  double focalLength() const { return focal_px_; }
  static double referenceSpread() { return DepthNoise::structuredLight().spread(1.0, 525.0); }

  /// The factor at depth z (1 where z <= 0: no reading). Exactly 1 up to unitDepth(), without
  /// arithmetic, so that per-pixel use costs nothing on near data.
  double at(double z) const { return z <= unit_depth_ ? 1.0 : std::max(1.0, ratio(z)); }
  double unitDepth() const { return unit_depth_; }

  /// The spread of one reading at depth z (DepthNoise::spread).
  double spread(double z) const { return noise_.spread(z, focal_px_); }

  /// `tolerance` widened for a reading at depth z.
  float widen(float tolerance, float z) const { return z <= unit_depth_ ? tolerance : float(tolerance * at(z)); }

  /// The factor at the median of `depths` (the readings of one object in one frame), 1 for none.
  double atMedian(std::vector<float> depths) const {
    if (depths.empty()) return 1.0;
    const auto middle = depths.begin() + std::ptrdiff_t(depths.size() / 2);
    std::nth_element(depths.begin(), middle, depths.end());
    return at(*middle);
  }

  /// The factor of a comparison between two readings of scales a and b: the spread of their
  /// difference over that of two reference readings.
  static double between(double a, double b) { return std::sqrt(0.5 * (a * a + b * b)); }

 private:
  double ratio(double z) const { return noise_.spread(z, focal_px_) / referenceSpread(); }

  DepthNoise noise_;
  double focal_px_;
  double unit_depth_ = 0.0;
};

}  // namespace bundletrack
