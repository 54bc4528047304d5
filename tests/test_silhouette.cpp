// The silhouette image against distances worked out by hand, and which points the silhouette
// term counts.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "bundletrack/core/silhouette_image.hpp"
#include "bundletrack/residuals/dense_silhouette.hpp"

namespace bt = bundletrack;

namespace {

const bt::PinholeCameraf kCamera{100.0f, 100.0f, 49.5f, 39.5f};

/// A 100 x 80 frame: the object a rectangle of columns 30-49 and rows 20-39 at 1 m before a wall at
/// 2 m, an occluder at 0.5 m over columns 60-69 and rows 20-39 (not in the mask) whose rim, columns
/// 58-59, has no reading, no reading in columns 30-49 of rows 45-54 (beyond the sensor's range), a
/// surface at 0.995 m over columns 30-49 of rows 5-14, and rows 60-79 beyond the depth camera's view.
bt::RgbdFrame rectangleFrame() {
  bt::RgbdFrame frame;
  frame.mask = cv::Mat::zeros(80, 100, CV_8UC1);
  frame.mask(cv::Rect(30, 20, 20, 20)).setTo(255);
  frame.depth = cv::Mat(80, 100, CV_32FC1, cv::Scalar(2.0f));
  frame.depth(cv::Rect(30, 20, 20, 20)).setTo(1.0f);
  frame.depth(cv::Rect(60, 20, 10, 20)).setTo(0.5f);
  frame.depth(cv::Rect(58, 20, 2, 20)).setTo(0.0f);
  frame.depth(cv::Rect(30, 45, 20, 10)).setTo(0.0f);
  frame.depth(cv::Rect(30, 5, 20, 10)).setTo(0.995f);
  frame.depth.rowRange(60, 80).setTo(0.0f);
  frame.depth_view = bt::depthCameraView(frame.depth);
  REQUIRE(frame.depth_view == cv::Rect(0, 0, 100, 60));
  frame.points.create(80, 100, CV_32FC3);
  for (int v = 0; v < 80; ++v)
    for (int u = 0; u < 100; ++u) {
      const Eigen::Vector3f p = kCamera.unproject(float(u), float(v), frame.depth.at<float>(v, u));
      frame.points.at<cv::Vec3f>(v, u) = {p.x(), p.y(), p.z()};
    }
  return frame;
}

}  // namespace

TEST_CASE("the silhouette image is the signed distance to the mask's outline") {
  bt::RgbdFrame frame = rectangleFrame();
  const bt::SilhouetteImage image = bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::every_pixel, 2, 10);
  CHECK(image.box == cv::Rect(20, 10, 40, 40));
  const auto distance = [&](double u, double v) {
    double d = 0.0, du = 0.0, dv = 0.0;
    REQUIRE(image.sample(u, v, d, du, dv));
    return d;
  };
  // The outline lies half a pixel beyond the outermost mask pixels (column 49, row 39).
  CHECK(distance(49.5, 30.0) == doctest::Approx(0.0).epsilon(1e-6));
  CHECK(distance(53.0, 30.0) == doctest::Approx(3.5));
  CHECK(distance(30.0, 16.0) == doctest::Approx(3.5));
  CHECK(distance(52.0, 43.0) == doctest::Approx(5.0 - 0.5).epsilon(1e-5));  // from the corner pixel (49, 39): 3, 4, 5
  CHECK(distance(40.0, 30.0) == doctest::Approx(0.5 - 10.0));  // inside: 10 pixels from column 50 and row 40
  double d = 0.0, du = 0.0, dv = 0.0;
  REQUIRE(image.sample(53.0, 30.0, d, du, dv));
  CHECK(du == doctest::Approx(1.0));
  CHECK(dv == doctest::Approx(0.0));
  CHECK_FALSE(image.sample(15.0, 30.0, d, du, dv));  // beyond the margin
  // Deep inside: more than 2.5 px from the outline's pixels (the quick test before sampling).
  CHECK(image.deepInside(40.2, 30.4));
  CHECK(image.deepInside(47.0, 30.0));  // 3 px from column 50, off the mask
  CHECK_FALSE(image.deepInside(48.0, 30.0));  // 2 px
  CHECK_FALSE(image.deepInside(53.0, 30.0));
  // Points every second pixel of the mask, in the camera frame; the depth for the occlusion test.
  CHECK(image.points.size() == 10 * 10);
  CHECK(image.points.front() == frame.points.at<cv::Vec3f>(20, 30));
  CHECK(image.depthAt(40, 30) == 1.0f);
  CHECK(image.depthAt(0, 0) == 0.0f);
  // Without a reading: unknown next to a reading off the mask (the occluder's rim, a dropout by
  // the wall: the wall's row 44 lies within 4 px of row 47), past the sensor's range off the mask
  // where there is none within 4 px; on the mask nothing.
  CHECK(image.depthAt(58, 30) == 0.0f);
  CHECK(image.depthAt(40, 47) == 0.0f);
  CHECK(image.depthAt(40, 49) == std::numeric_limits<float>::infinity());
  frame.depth.at<float>(30, 40) = 0.0f;
  CHECK(bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::every_pixel, 2, 10).depthAt(40, 30) == 0.0f);
  // A mask grown over depth never holds a pixel without a reading: one off it may be the object's.
  const bt::SilhouetteImage over_depth = bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::where_depth_read, 2, 10);
  CHECK(over_depth.depthAt(58, 30) == 0.0f);
  CHECK(over_depth.depthAt(40, 49) == 0.0f);
  CHECK(over_depth.depthAt(53, 30) == 2.0f);
  CHECK(bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::none, 2, 10).empty());
}

TEST_CASE("the silhouette term counts a point outside the outline only where the frame sees past it") {
  // Past it: a reading farther than the point by three standard deviations of two readings'
  // difference. A nearer reading may be an occluder that the mask leaves out, one as near as the
  // point the object itself where the mask misses it; without a reading off the mask within 4 px
  // the frame saw nothing within the sensor's range there, next to one (a dropout, a rim) or beyond
  // the depth camera's view nothing is known.
  const bt::RgbdFrame frame = rectangleFrame();
  bt::SilhouetteImage t = bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::every_pixel, 1, 25);
  t.points.clear();  // one direction only: s's points into t
  bt::SurfaceGrid grid;  // what the term reads of the grids: camera, step and noise scale
  grid.camera = kCamera;
  bt::SilhouetteImage s;
  s.samples = cv::Mat(1, 1, CV_32FC3, cv::Scalar::all(0));
  const auto at = [](float u, float v, float z) {
    const Eigen::Vector3f p = kCamera.unproject(u, v, z);
    return cv::Vec3f(p.x(), p.y(), p.z());
  };
  // Three standard deviations of two readings' difference at 1 m (structured light, noise scale 1).
  const double margin = 3.0 * std::sqrt(2.0) * bt::NoiseScale::referenceSpread();
  REQUIRE(margin > 0.005);
  REQUIRE(margin < 0.015);
  s.points = {at(40, 30, 1.0f),  // inside the outline
              at(53, 30, 1.0f),  // 3.5 px outside, the wall behind it: counts
              at(40, 12, 1.0f),  // 7.5 px outside, a reading 5 mm nearer: the object's own surface as far
                                 // as the noise tells, which the mask misses: does not count
              at(36, 12, 0.98f),  // 7.5 px outside, a reading 15 mm farther: the frame saw past it, counts
              at(44, 12, 1.03f),  // outside, a reading 35 mm nearer: it may hide the point
              at(40, 50, 1.0f),  // 10.5 px outside, no reading there nor within 4 px: counts
              at(58, 30, 1.0f),  // outside, on the occluder's rim without a reading: unknown
              at(64, 30, 1.0f),  // outside, behind the occluder
              at(40, 64, 1.0f),  // outside, beyond the depth camera's view (and 5 px from its last row)
              at(90, 30, 1.0f)};  // beyond the silhouette image
  const bt::DenseSilhouette term;
  bt::PairSystem system;
  term.linearise(bt::DenseSilhouette::Input{grid, s, grid, t}, bt::SE3d(), bt::SE3d(), bt::TrivialLoss{}, 1.0, system);
  CHECK(system.residuals == 3);  // (53, 30), (36, 12) and (40, 50)
  // Its weight: (reference spread / sigma)^2 x step / 4 at noise scale 1, step 1 (one camera: a depth
  // error moves the point along t's ray, not across the outline).
  const double weight = std::pow(bt::NoiseScale::referenceSpread() / term.sigma, 2) / 4.0;
  CHECK(system.cost == doctest::Approx(weight * (3.5 * 3.5 + 7.5 * 7.5 + 10.5 * 10.5)));
}

TEST_CASE("a mask grown onto the background gives the silhouette none of the background's points") {
  // The rectangle's mask grown by 3 px over the wall 1 m behind it: those pixels lie behind a
  // depth edge within the mask, farther than the nearest mask reading within 4 px by more than the
  // noise and a steep surface's rise, and are not the object's.
  bt::RgbdFrame frame = rectangleFrame();
  const bt::SilhouetteImage exact = bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::every_pixel, 2, 10);
  cv::dilate(frame.mask, frame.mask, cv::Mat::ones(7, 7, CV_8UC1));
  const bt::SilhouetteImage grown = bt::makeSilhouetteImage(frame, frame.mask, bt::MaskOutline::every_pixel, 2, 10);
  REQUIRE(grown.box.width > exact.box.width);  // the outline is the grown mask's
  CHECK(grown.points.size() == exact.points.size());
  for (const cv::Vec3f& p : grown.points) CHECK(p[2] == 1.0f);
}
