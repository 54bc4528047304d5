// Object crops, feature sources and the coarse tracker on synthetic sequences with exact ground truth.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "bundletrack/default_tracker.hpp"
#include "bundletrack/eval/pose_metrics.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

namespace {

bt::RgbdFrame syntheticFrame(const synth::SyntheticScene& scene, int i) {
  const synth::SyntheticFrame f = scene.frame(i);
  return bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, scene.settings().camera.cast<float>());
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

TEST_CASE("object crop maps crop pixels back onto the full-resolution pixels they show") {
  // A single bright pixel at a known place must land at the crop's brightest pixel, and mapping
  // that crop pixel back must return the original within half a crop pixel.
  for (const cv::Point target : {cv::Point(200, 150), cv::Point(203, 171)}) {
    cv::Mat image(240, 320, CV_8UC3, cv::Scalar::all(0));
    image.at<cv::Vec3b>(target) = cv::Vec3b(255, 255, 255);
    cv::Mat mask(240, 320, CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(190, 140, 30, 40)).setTo(255);
    const bt::ObjectCrop crop = bt::makeObjectCrop(image, mask, 400, 0);
    CHECK(crop.scale == doctest::Approx(10.0));  // the 40-pixel side becomes 400
    cv::Point brightest;
    cv::minMaxLoc(crop.gray, nullptr, nullptr, nullptr, &brightest);
    const cv::Point2f back = crop.toImage(cv::Point2f(brightest));
    CHECK(std::abs(back.x - float(target.x)) <= 0.5f / 10.0f + 1e-4f);
    CHECK(std::abs(back.y - float(target.y)) <= 0.5f / 10.0f + 1e-4f);
  }
}

TEST_CASE("detecting features leaves the frame's mask untouched and keeps keypoints on the object") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 10;
  const synth::SyntheticScene scene(settings);
  const bt::RgbdFrame frame = syntheticFrame(scene, 3);
  const cv::Mat mask_before = frame.mask.clone();
  bt::SiftFeatures sift;
  const bt::FrameFeatures features = sift.detect(frame);
  CHECK(cv::countNonZero(frame.mask != mask_before) == 0);
  CHECK(features.size() > 100);  // a richly printed 10 x 16 cm box at 0.68 m
  CHECK(features.descriptors.rows == int(features.size()));
  // Every lifted point lies on the box: within 5 mm (several sigma of the sensor noise) of its surface.
  const bt::SE3d T_obj_cam = scene.T_cam_obj(3).inverse();
  for (const auto& p : features.points) {
    const Eigen::Vector3d q = (T_obj_cam * p.cast<double>()).cwiseAbs();
    const Eigen::Vector3d half(0.05, 0.035, 0.08);
    const double outside = (q - half).cwiseMax(0.0).norm(), inside = (half - q).minCoeff();
    CHECK(std::max(outside, inside) < 0.005);
  }
}

TEST_CASE_TEMPLATE("coarse tracker: per-frame relative pose errors on a synthetic hand-held box", Source,
                   bt::SiftFeatures, bt::OrbFeatures, bt::AkazeFeatures) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 30;
  settings.speed = 2.0;  // ~2 deg and ~5 mm per frame: a tracker that misses the motion fails the bounds
  const synth::SyntheticScene scene(settings);
  bt::CoarseTracker<Source, bt::Ransac> tracker;
  tracker.initialize(syntheticFrame(scene, 0), scene.T_cam_obj(0));
  bt::SE3d previous_estimate = scene.T_cam_obj(0);
  std::vector<double> rotation, translation, step;
  int lost = 0;
  for (int i = 1; i < settings.frames; ++i) {
    const bt::TrackResult result = tracker.track(syntheticFrame(scene, i));
    lost += result.status == bt::TrackStatus::Lost;
    // The step's own error: the estimated motion applied to the true previous pose, compared in
    // the object frame, so the rotation's lever arm about the camera does not enter.
    const bt::SE3d delta = result.T_cam_obj * previous_estimate.inverse();
    const bt::SE3d error = scene.T_cam_obj(i).inverse() * delta * scene.T_cam_obj(i - 1);
    rotation.push_back(error.rotation().angle() * 180.0 / 3.141592653589793);
    translation.push_back(error.translation().norm());
    step.push_back(rotationGeodesic(scene.T_cam_obj(i).rotation(), scene.T_cam_obj(i - 1).rotation()) * 180.0 /
                   3.141592653589793);
    previous_estimate = result.T_cam_obj;
  }
  const double median_rotation = median(rotation), median_translation = median(translation);
  MESSAGE("median per-frame error: " << median_rotation << " deg, " << 1e3 * median_translation << " mm; lost "
                                     << lost);
  CHECK(lost == 0);
  // Noise floor: ~50 inliers with ~2 mm residuals spread over +-6 cm give sigma_rot ~ 2 / (60 sqrt 50)
  // rad = 0.27 deg and sigma_t ~ 0.3 mm; the bounds allow 3-4x that, and stay well below the motion
  // itself (median step checked below), so a tracker that misses or inverts the motion fails.
  CHECK(median(step) > 1.5);
  CHECK(median_rotation < 1.0);
  CHECK(median_translation < 0.002);
}

TEST_CASE("coarse tracker reports lost frames instead of repeating the pose silently") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 10;
  const synth::SyntheticScene scene(settings);
  bt::DefaultCoarseTracker tracker;
  tracker.initialize(syntheticFrame(scene, 0), scene.T_cam_obj(0));
  bt::RgbdFrame hidden = syntheticFrame(scene, 1);
  hidden.mask.setTo(0);  // the object is gone from view
  const bt::TrackResult lost = tracker.track(hidden);
  CHECK(lost.status == bt::TrackStatus::Lost);
  CHECK(lost.inliers == 0);
  // It comes back: matching resumes against the last good frame.
  const bt::TrackResult back = tracker.track(syntheticFrame(scene, 2));
  CHECK(back.status == bt::TrackStatus::CoarseOnly);
  CHECK(bt::translationError(back.T_cam_obj, scene.T_cam_obj(2)) < 0.005);
}

TEST_CASE("optical flow follows keypoints into the next frame to where the true motion takes them") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 6;
  settings.speed = 2.0;  // ~2 deg and ~5 mm per frame: ~6 px of image motion at 0.7 m
  const synth::SyntheticScene scene(settings);
  const bt::PinholeCamerad camera = settings.camera;
  const bt::RgbdFrame before = syntheticFrame(scene, 3), after = syntheticFrame(scene, 4);
  bt::SiftFeatures sift;
  const bt::FrameFeatures detected = sift.detect(before);
  REQUIRE(detected.size() > 100);
  cv::Mat gray, gray_after;
  cv::cvtColor(before.color, gray, cv::COLOR_BGR2GRAY);
  cv::cvtColor(after.color, gray_after, cv::COLOR_BGR2GRAY);
  const bt::FollowedFeatures followed = sift.follow(gray, before.mask, detected, after, gray_after);
  REQUIRE(followed.matches.size() == followed.features.size());
  // Where each keypoint truly goes: its pixel lifted with the renderer's exact depth, moved by the
  // exact relative pose, projected (the depth of the nearest pixel centre: < 1 mm off on these
  // faces, which moves a projection by < 0.01 px under this motion).
  const cv::Mat exact_depth = scene.renderClean(3).depth;
  const bt::SE3d T_after_before = scene.T_cam_obj(4) * scene.T_cam_obj(3).inverse();
  std::vector<double> errors, motion;
  for (std::size_t i = 0; i < followed.matches.size(); ++i) {
    const bt::FeatureMatch& m = followed.matches[i];
    CHECK(m.second == int(i));
    CHECK(cv::norm(followed.features.descriptors.row(int(i)), detected.descriptors.row(m.first), cv::NORM_L2) == 0.0);
    const cv::Point2f from = detected.pixels[std::size_t(m.first)];
    const double z = exact_depth.at<float>(bt::roundToPixel(from.y), bt::roundToPixel(from.x));
    const Eigen::Vector2d to = camera.project(T_after_before * camera.unproject(from.x, from.y, z));
    const cv::Point2f found = followed.features.pixels[i];
    errors.push_back(std::hypot(found.x - to.x(), found.y - to.y()));
    motion.push_back(std::hypot(to.x() - from.x, to.y() - from.y));
  }
  std::sort(errors.begin(), errors.end());
  const double median_error = errors[errors.size() / 2], p90 = errors[errors.size() * 9 / 10];
  MESSAGE(followed.features.size() << " of " << followed.tried << " keypoints followed (" << detected.size()
                                   << " detected); error median " << median_error
                                   << " px, 90th percentile " << p90 << " px; image motion median " << median(motion) << " px");
  // Only keypoints whose flow window lies on the object are tried: on this 10 x 16 cm box at
  // 0.7 m (~90 x 140 px) about half of them.
  CHECK(followed.tried >= int(detected.size()) / 3);
  // Most of those survive one frame; the survivors land within a fraction of a pixel (Lucas-Kanade
  // on a textured surface with sensor noise: ~0.1 px; SIFT's own localisation is ~0.5 px), far
  // less than the motion, so a follower that stood still or went astray fails.
  CHECK(followed.features.size() >= std::size_t(followed.tried) * 3 / 4);
  CHECK(median(motion) > 3.0);
  CHECK(median_error < 0.25);
  CHECK(p90 < 0.6);
  // Followed keypoints must land on the frame's mask: into a frame without the object, none do.
  bt::RgbdFrame elsewhere = after;
  elsewhere.mask = cv::Mat::zeros(after.mask.size(), CV_8UC1);
  CHECK(sift.follow(gray, before.mask, detected, elsewhere, gray_after).features.size() == 0);
}
