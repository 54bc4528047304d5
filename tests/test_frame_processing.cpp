// Camera model, depth clean-up and normals against analytic geometry.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include "bundletrack/core/disc_dilation.hpp"
#include "bundletrack/core/frame_memory.hpp"
#include "bundletrack/core/intensity_image.hpp"
#include "bundletrack/core/rgbd_frame.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/core/surface_grid.hpp"
#include "bundletrack/io/frame_ahead.hpp"

namespace bt = bundletrack;

namespace {

const bt::PinholeCameraf kCamera{500.0f, 510.0f, 63.5f, 47.25f};

// Depth of the plane n . p = d seen through kCamera: z = d / (n . K^-1 [u v 1]).
cv::Mat planeDepth(const Eigen::Vector3f& n, float d, cv::Size size) {
  cv::Mat depth(size, CV_32FC1);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      depth.at<float>(v, u) = d / n.dot(kCamera.unproject(float(u), float(v), 1.0f));
  return depth;
}

}  // namespace

TEST_CASE("pinhole projection is K p / z and unprojection inverts it") {
  const Eigen::Vector3f p(0.12f, -0.07f, 0.9f);
  const Eigen::Vector3f Kp = kCamera.matrix() * p;
  const Eigen::Vector2f uv = kCamera.project(p);
  CHECK(uv.x() == doctest::Approx(Kp.x() / Kp.z()).epsilon(1e-6));
  CHECK(uv.y() == doctest::Approx(Kp.y() / Kp.z()).epsilon(1e-6));
  CHECK((kCamera.unproject(uv.x(), uv.y(), p.z()) - p).norm() < 1e-6f);
}

TEST_CASE("pixels are rounded half away from zero as std::lround does, and far or NaN coordinates fall outside") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-2000.0, 2000.0);
  for (int k = 0; k < 100000; ++k) {
    const double x = coordinate(rng);
    REQUIRE(bt::roundToPixel(x) == std::lround(x));
    REQUIRE(bt::roundToPixel(float(x)) == std::lround(float(x)));
  }
  for (const double tie : {-2.5, -1.5, -0.5, 0.5, 1.5, 2.5, 639.5})  // the cases rounding modes differ in
    CHECK(bt::roundToPixel(tie) == std::lround(tie));
  CHECK(bt::roundToPixel(std::nextafter(0.5, 0.0)) == 0);
  CHECK(bt::roundToPixel(std::nextafter(-0.5, 0.0)) == 0);
  for (const double far : {3e9, -3e9, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    CHECK(bt::roundToPixel(far) < -1000000000);
}

TEST_CASE("unprojected depth of a plane lies on the plane and its normals are the plane's") {
  const Eigen::Vector3f n = Eigen::Vector3f(0.2f, -0.3f, -1.0f).normalized();  // faces the camera
  const float d = -0.8f;  // n . p = d, p about 0.8 m in front of the camera
  const cv::Mat depth = planeDepth(n, d, {128, 96});
  const cv::Mat points = bt::unprojectDepth(depth, kCamera);
  const cv::Mat normals = bt::estimateNormals(points);
  int checked = 0;
  for (int v = 1; v + 1 < depth.rows; ++v) {
    for (int u = 1; u + 1 < depth.cols; ++u) {
      const cv::Vec3f& p = points.at<cv::Vec3f>(v, u);
      const cv::Vec3f& m = normals.at<cv::Vec3f>(v, u);
      REQUIRE(std::abs(n.dot(Eigen::Vector3f(p[0], p[1], p[2])) - d) < 1e-5f);
      REQUIRE(Eigen::Vector3f(m[0], m[1], m[2]).dot(n) > 1.0f - 1e-5f);
      ++checked;
    }
  }
  CHECK(checked == 126 * 94);
}

TEST_CASE("normals are undefined across a depth discontinuity larger than the jump limit") {
  cv::Mat depth(32, 32, CV_32FC1, cv::Scalar(0.6f));
  depth.colRange(16, 32).setTo(0.7f);  // a 10 cm step
  const cv::Mat normals = bt::estimateNormals(bt::unprojectDepth(depth, kCamera), 0.02f);
  CHECK(cv::norm(normals.at<cv::Vec3f>(10, 15)) == 0.0);
  CHECK(cv::norm(normals.at<cv::Vec3f>(10, 16)) == 0.0);
  CHECK(cv::norm(normals.at<cv::Vec3f>(10, 14)) == doctest::Approx(1.0));
  CHECK(normals.at<cv::Vec3f>(10, 14)[2] == doctest::Approx(-1.0));  // fronto-parallel, facing the camera
}

TEST_CASE("erosion removes isolated readings and flying pixels but keeps smooth surfaces") {
  bt::DepthFilterSettings settings;
  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(0.0f));
  depth.at<float>(3, 3) = 0.5f;  // isolated speckle
  depth(cv::Rect(8, 8, 10, 10)).setTo(0.9f);  // a flat patch
  depth.at<float>(12, 12) = 0.95f;  // a flying pixel 5 cm off the patch
  const cv::Mat eroded = bt::erodeDepth(depth, settings);
  CHECK(eroded.at<float>(3, 3) == 0.0f);
  CHECK(eroded.at<float>(12, 12) == 0.0f);
  CHECK(eroded.at<float>(10, 10) == 0.9f);  // interior
  CHECK(eroded.at<float>(8, 12) == 0.9f);  // border pixel: 3 of 8 neighbours invalid, below 80%
  CHECK(eroded.at<float>(8, 8) == 0.9f);  // corner pixel: 5 of 8, still below 80%
}

TEST_CASE("smoothing reduces sensor noise on a plane and keeps depth steps") {
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  cv::Mat truth(64, 64, CV_32FC1, cv::Scalar(0.8f));
  truth.colRange(32, 64).setTo(1.0f);  // a 20 cm step, far above the 1 cm window
  cv::Mat noisy = truth.clone();
  for (int v = 0; v < noisy.rows; ++v)
    for (int u = 0; u < noisy.cols; ++u) noisy.at<float>(v, u) += noise(rng);
  for (const bt::DepthSmoothing smoothing : {bt::DepthSmoothing::Mean, bt::DepthSmoothing::PlaneFit}) {
    CAPTURE(int(smoothing));
    bt::DepthFilterSettings settings;
    settings.smoothing = smoothing;
    cv::Mat smoothed = noisy;
    for (int pass = 0; pass < settings.smooth_passes; ++pass) smoothed = bt::smoothDepth(smoothed, settings);
    const cv::Rect left(4, 4, 24, 56), right(36, 4, 24, 56);
    const double rms_before = cv::norm(noisy(left), truth(left)) / std::sqrt(double(left.area()));
    const double rms_after = cv::norm(smoothed(left), truth(left)) / std::sqrt(double(left.area()));
    CHECK(rms_after < 0.5 * rms_before);
    // Next to the step each side keeps its own level (a blurred step would read ~0.9 m there); the
    // bound is 4 sigma of the raw noise because edge pixels may keep their raw reading.
    for (int v = 4; v < 60; ++v) {
      CHECK(std::abs(smoothed.at<float>(v, 31) - 0.8f) < 0.008f);
      CHECK(std::abs(smoothed.at<float>(v, 32) - 1.0f) < 0.008f);
    }
    // Away from the step the averaged noise (sigma ~0.7 mm) stays well under 4 mm everywhere.
    CHECK(cv::norm(smoothed(right), truth(right), cv::NORM_INF) < 0.004);
  }
}

TEST_CASE("plane-fit smoothing keeps a slanted plane where the mean flattens it at a border") {
  // A plane turned 60 degrees about the camera's y axis (3.5 mm of depth per pixel at 1 m), its
  // right half invalid: next to the border the window holds neighbours on one side only. The
  // mean moves those pixels by slope x the neighbours' mean offset (millimetres); the plane
  // through them is the true plane, up to the depth's curvature in pixel coordinates (z is
  // hyperbolic in u) and float rounding. Interior pixels: both stay on the plane.
  const Eigen::Vector3f n = Eigen::Vector3f(std::sin(1.0472f), 0.0f, -std::cos(1.0472f)).normalized();
  cv::Mat truth = planeDepth(n, -0.5f, {64, 64});
  cv::Mat cut = truth.clone();
  cut.colRange(32, 64).setTo(0.0f);
  REQUIRE(truth.at<float>(32, 31) == doctest::Approx(1.0).epsilon(0.1));
  const auto error = [&](bt::DepthSmoothing smoothing, cv::Rect where) {
    bt::DepthFilterSettings settings;
    settings.smoothing = smoothing;
    cv::Mat smoothed = cut;
    for (int pass = 0; pass < settings.smooth_passes; ++pass) smoothed = bt::smoothDepth(smoothed, settings);
    return cv::norm(smoothed(where), truth(where), cv::NORM_INF);
  };
  const cv::Rect border(30, 4, 2, 56), interior(8, 8, 16, 48);
  CHECK(error(bt::DepthSmoothing::Mean, border) > 0.002);
  CHECK(error(bt::DepthSmoothing::PlaneFit, border) < 0.0002);
  CHECK(error(bt::DepthSmoothing::PlaneFit, interior) < 0.0002);
}

TEST_CASE("range check zeroes non-finite and out-of-range depth") {
  bt::DepthFilterSettings settings;
  settings.max_depth = 3.0f;
  cv::Mat depth = (cv::Mat_<float>(1, 5) << 0.05f, std::numeric_limits<float>::quiet_NaN(), 1.0f,
                   std::numeric_limits<float>::infinity(), 4.0f);
  bt::invalidateOutOfRange(depth, settings);
  CHECK(cv::countNonZero(depth) == 1);
  CHECK(depth.at<float>(0, 2) == 1.0f);
}

TEST_CASE("a frame preprocessed inside a region equals the whole image's preprocessing there, zero elsewhere") {
  // A slanted plane with noise, steps and holes: every filter (erosion, both smoothing passes,
  // normals) has work at the regions' borders.
  const cv::Size size(128, 96);
  cv::Mat depth = planeDepth(Eigen::Vector3f(0.2f, -0.3f, -1.0f).normalized(), -0.8f, size);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  std::uniform_int_distribution<int> hole(0, 9);
  for (auto it = depth.begin<float>(); it != depth.end<float>(); ++it) *it = hole(rng) == 0 ? 0.0f : *it + noise(rng);
  depth(cv::Rect(40, 20, 30, 40)) += 0.08f;  // a step farther than every depth window
  const cv::Mat color(size, CV_8UC3, cv::Scalar::all(128));
  bt::FrameSettings settings;
  settings.sensor = bt::DepthNoise::activeStereo();  // tolerances that vary with depth
  const bt::RgbdFrame whole = bt::makeFrame("whole", color, depth, cv::Mat(), kCamera, settings);
  CHECK(whole.region == cv::Rect({0, 0}, size));
  for (const cv::Rect region : {cv::Rect(30, 15, 50, 45), cv::Rect(0, 0, 20, 96), cv::Rect(100, 70, 60, 60)}) {
    const bt::RgbdFrame part = bt::makeFrame("part", color, depth, cv::Mat(), kCamera, settings, region);
    const cv::Rect inside = region & cv::Rect({0, 0}, size);
    CAPTURE(inside);
    CHECK(part.region == inside);
    CHECK(cv::countNonZero(part.depth(inside)) > inside.area() / 2);
    CHECK(cv::norm(part.depth(inside), whole.depth(inside), cv::NORM_INF) == 0.0);
    CHECK(cv::norm(part.points(inside), whole.points(inside), cv::NORM_INF) == 0.0);
    CHECK(cv::norm(part.normals(inside), whole.normals(inside), cv::NORM_INF) == 0.0);
    cv::Mat outside(size, CV_8UC1, cv::Scalar(255));
    outside(inside).setTo(0);
    for (const cv::Mat& image : {part.depth, part.points, part.normals}) {
      cv::Mat left = cv::Mat::zeros(size, image.type());
      image.copyTo(left, outside);
      CHECK(cv::countNonZero(left.reshape(1)) == 0);
    }
    // The surface grid of a mask inside the region visits only the region's cells (odd offsets:
    // the first cell at or after the region's first pixel) and equals the whole frame's.
    cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
    mask(inside).setTo(255);
    for (const int step : {1, 2, 3}) {
      const bt::SurfaceGrid from_part = bt::sampleSurface(part, mask, kCamera, step);
      const bt::SurfaceGrid from_whole = bt::sampleSurface(whole, mask, kCamera, step);
      CAPTURE(step);
      CHECK(from_part.cells.size() > std::size_t(inside.area() / (4 * step * step)));  // not empty: a tenth are holes
      CHECK(from_part.cells == from_whole.cells);
      CHECK(cv::norm(from_part.points, from_whole.points, cv::NORM_INF) == 0.0);
      CHECK(cv::norm(from_part.normals, from_whole.normals, cv::NORM_INF) == 0.0);
    }
  }
}

TEST_CASE("the depth camera's view is the bounding box of the raw depth's readings") {
  // A depth image registered to a wider colour camera: no reading in its first 3 and last 5 columns
  // and its first 2 and last 4 rows; within them, a far background without readings (rows 10-30).
  cv::Mat raw(40, 60, CV_32FC1, cv::Scalar(1.5f));
  raw.colRange(0, 3).setTo(0.0f);
  raw.colRange(55, 60).setTo(0.0f);
  raw.rowRange(0, 2).setTo(0.0f);
  raw.rowRange(36, 40).setTo(0.0f);
  raw.rowRange(10, 30).setTo(0.0f);
  CHECK(bt::depthCameraView(raw) == cv::Rect(3, 2, 52, 34));
  raw.at<float>(0, 59) = std::numeric_limits<float>::quiet_NaN();  // not a reading
  raw.at<float>(38, 1) = 2.0f;  // one reading stretches the box to it
  CHECK(bt::depthCameraView(raw) == cv::Rect(1, 2, 54, 37));
  CHECK(bt::depthCameraView(cv::Mat::zeros(40, 60, CV_32FC1)).empty());
  // makeFrame keeps it whatever region it preprocesses.
  CHECK(bt::makeFrame("0", cv::Mat(40, 60, CV_8UC3), raw, {}, kCamera, {}, cv::Rect(20, 20, 5, 5)).depth_view ==
        cv::Rect(1, 2, 54, 37));
}

TEST_CASE("a frame preprocessed ahead is used where the tracker asks for its region, and made again elsewhere") {
  const cv::Size size(128, 96);
  const cv::Mat depth = planeDepth(Eigen::Vector3f(0.1f, 0.2f, -1.0f).normalized(), -0.9f, size);
  const cv::Mat color(size, CV_8UC3, cv::Scalar::all(128));
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  mask(cv::Rect(50, 30, 20, 25)).setTo(255);
  const cv::Rect foretold = bt::maskRegion(mask, size);
  CHECK(foretold == cv::Rect(50 - bt::kRegionMargin, 30 - bt::kRegionMargin, 20 + 2 * bt::kRegionMargin,
                             25 + 2 * bt::kRegionMargin));
  int made = 0;
  const auto preprocess = [&](bt::RawFrame raw, const cv::Rect& region) {
    ++made;
    return bt::makeFrame(std::move(raw), kCamera, {}, region);
  };
  const bt::RawFrame raw{"0", color, depth, mask};
  for (const cv::Rect asked : {foretold, cv::Rect(), cv::Rect(10, 10, 40, 40)}) {
    CAPTURE(asked);
    made = 0;
    bt::io::FrameAhead ahead = bt::io::frameAhead(raw, foretold, preprocess);
    const float* made_ahead = ahead.preprocessed->depth.ptr<float>();
    const bt::RgbdFrame frame = bt::io::preprocessedOver(std::move(ahead), asked, preprocess);
    const bt::RgbdFrame reference = bt::makeFrame(raw, kCamera, {}, asked);
    const bool same_region = asked == foretold;
    CHECK(made == (same_region ? 1 : 2));
    CHECK((frame.depth.ptr<float>() == made_ahead) == same_region);
    CHECK(frame.region == reference.region);
    CHECK(cv::norm(frame.depth, reference.depth, cv::NORM_INF) == 0.0);
    CHECK(cv::norm(frame.normals, reference.normals, cv::NORM_INF) == 0.0);
    CHECK(cv::countNonZero(frame.mask != mask) == 0);
  }
  // Nothing foretold (masks propagated by the tracker): the frame is made when asked for.
  made = 0;
  const bt::RgbdFrame frame = bt::io::preprocessedOver(bt::io::frameAhead(raw, std::nullopt, preprocess), foretold, preprocess);
  CHECK(made == 1);
  CHECK(frame.region == foretold);
}

TEST_CASE("the intensity image drops shading and the background and holds each grid cell's intensity") {
  // An object (mask: a rectangle) under linear shading, grey 0.3 + 0.002 u, on a white background.
  const cv::Size size(120, 100);
  const cv::Rect object(20, 20, 80, 60);
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1), bgr(size, CV_8UC3, cv::Scalar::all(255));
  mask(object).setTo(255);
  for (int v = object.y; v < object.br().y; ++v)
    for (int u = object.x; u < object.br().x; ++u) bgr.at<cv::Vec3b>(v, u) = cv::Vec3b::all(uchar(std::lround(255.0 * (0.3 + 0.002 * u))));
  const bt::IntensityImage image = bt::makeIntensityImage(bgr, mask, 4);
  REQUIRE(image.box == cv::Rect(16, 16, 88, 68));
  // Valid: the mask eroded by 2 px.
  const auto valid = [&](int u, int v) { return image.valid.at<uchar>(v - image.box.y, u - image.box.x) != 0; };
  CHECK(valid(object.x + 2, 50));
  CHECK_FALSE(valid(object.x + 1, 50));
  CHECK_FALSE(valid(object.br().x - 2, 50));
  CHECK(valid(object.br().x - 3, 50));
  // The local mean of a linear ramp is the ramp: inside, the image is the 8-bit rounding alone
  // (< 0.5 / 255 ~ 0.002), where the raw grey spans 0.16. Near the border the mean is over object
  // pixels only, so the white background (0.7 brighter) leaves little: a 3x3 smoothing's share.
  double worst_inside = 0.0, worst_border = 0.0;
  for (int v = object.y + 2; v < object.br().y - 2; ++v)
    for (int u = object.x + 2; u < object.br().x - 2; ++u) {
      double value = 0.0, du = 0.0, dv = 0.0;
      REQUIRE(image.sample(u, v, value, du, dv) == (u < object.br().x - 3 && v < object.br().y - 3));
      const bool interior = cv::Rect(object.x + 10, object.y + 10, object.width - 20, object.height - 20).contains({u, v});
      const double magnitude = std::abs(image.samples.at<cv::Vec3f>(v - image.box.y, u - image.box.x)[0]);
      (interior ? worst_inside : worst_border) = std::max(interior ? worst_inside : worst_border, magnitude);
    }
  CHECK(worst_inside < 0.003);
  CHECK(worst_border < 0.05);
  // Bilinear sampling at a pixel corner is the mean of the four pixels around it.
  const auto at = [&](int u, int v) { return image.samples.at<cv::Vec3f>(v - image.box.y, u - image.box.x); };
  double value = 0.0, du = 0.0, dv = 0.0;
  REQUIRE(image.sample(40.5, 30.5, value, du, dv));
  const cv::Vec3f mean = 0.25f * (at(40, 30) + at(41, 30) + at(40, 31) + at(41, 31));
  CHECK(value == doctest::Approx(mean[0]).epsilon(1e-6));
  CHECK(du == doctest::Approx(mean[1]).epsilon(1e-6));
  CHECK(dv == doctest::Approx(mean[2]).epsilon(1e-6));
  // A grid's cells: those where the image is defined, each with its pixel's intensity.
  bt::SurfaceGrid grid;
  grid.step = 4;
  for (int y = 0; y < 25; ++y)
    for (int x = 0; x < 30; ++x)
      if (mask.at<uchar>(4 * y, 4 * x)) grid.cells.emplace_back(x, y);
  bt::IntensityImage sampled = image;
  sampled.sampleCells(grid);
  std::size_t next = 0;
  for (std::size_t k = 0; k < grid.cells.size(); ++k) {
    const int u = 4 * grid.cells[k].x, v = 4 * grid.cells[k].y;
    if (!image.sample(u, v, value, du, dv)) continue;
    REQUIRE(next < sampled.cells.size());
    CHECK(sampled.cells[next].cell == int(k));
    CHECK(sampled.cells[next].intensity == at(u, v)[0]);
    ++next;
  }
  CHECK(next == sampled.cells.size());
  CHECK(next > 200);
}

TEST_CASE("a mask dilated by a disc equals OpenCV's dilation by its elliptic structuring element") {
  // Scattered pixels (a 1 among them: any non-zero is set), a blob and pixels on the image's border,
  // so that discs are cut by the border and overlap; radii from none to larger than the image.
  std::mt19937 random(7);
  cv::Mat mask(60, 90, CV_8UC1, cv::Scalar(0));
  for (int k = 0; k < 12; ++k) mask.at<uchar>(int(random() % 60), int(random() % 90)) = 255;
  mask.at<uchar>(0, 89) = mask.at<uchar>(59, 0) = 255;
  mask.at<uchar>(30, 40) = 1;
  cv::circle(mask, {60, 20}, 6, cv::Scalar(255), cv::FILLED);
  for (const int radius : {0, 1, 3, 8, 17, 40, 100}) {
    CAPTURE(radius);
    cv::Mat expected;
    cv::dilate(mask, expected, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * radius + 1, 2 * radius + 1}));
    expected = expected > 0;
    CHECK(cv::countNonZero(bt::dilatedByDisc(mask, radius) != expected) == 0);
  }
  CHECK(cv::countNonZero(bt::dilatedByDisc(cv::Mat::zeros(60, 90, CV_8UC1), 5)) == 0);
}

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)  // the sanitizers' allocator has no mallinfo2
TEST_CASE("keepFreedFrameMemory serves a frame-sized block from the heap and keeps it when freed") {
  REQUIRE(bt::keepFreedFrameMemory());
  constexpr std::size_t kBlock = 16 << 20;  // two 640x480 point images
  const struct mallinfo2 before = mallinfo2();
  void* block = std::malloc(kBlock);
  REQUIRE(block != nullptr);
  std::memset(block, 1, kBlock);
  CHECK(mallinfo2().hblks == before.hblks);  // not a block of its own pages (mmap)
  std::free(block);
  CHECK(mallinfo2().fordblks >= kBlock);  // its memory stays free in the heap for the next frame
}
#endif
