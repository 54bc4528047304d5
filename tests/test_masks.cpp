// Mask propagation from the first mask: depth segments, the first view's hull, and the masks
// against the renderer's exact ones.
#include <doctest/doctest.h>

#include "bundletrack/eval/mask_iou.hpp"
#include "bundletrack/graph/keyframe.hpp"
#include "bundletrack/masks/propagated_masks.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

TEST_CASE("depth segments: two planes split at their depth step, joined across the sensor's resolution") {
  const bt::PinholeCameraf camera{500.0f, 500.0f, 39.5f, 29.5f};
  cv::Mat depth(60, 80, CV_32FC1, cv::Scalar(2.0f));
  depth(cv::Rect(20, 10, 30, 25)).setTo(1.5f);  // a 30 x 25 px patch 0.5 m in front of a wall
  depth.at<float>(0, 0) = 0.0f;
  for (int u = 60; u < 80; ++u) depth.col(u) += 0.02f * float(u - 59);  // 2 cm steps at 2 m: one surface
  const cv::Mat points = bt::unprojectDepth(depth, camera);
  cv::Mat labels;
  // Structured light at 2 m is 3.5 times noisier than at 1 m: the 1 cm continuity becomes 3.5 cm.
  const bt::NoiseScale noise(bt::DepthNoise::structuredLight(), 500.0);
  const auto segments = bt::segmentDepth(depth, points, 0.01f, noise, labels);
  REQUIRE(segments.size() == 2);
  CHECK(labels.at<int>(0, 0) == -1);
  const int patch = labels.at<int>(20, 30);
  CHECK(segments[std::size_t(patch)].pixels == 30 * 25);
  CHECK(segments[std::size_t(1 - patch)].pixels == 80 * 60 - 30 * 25 - 1);
  // The patch's 3-D box: x from pixel 20 to 49 at 1.5 m.
  CHECK(segments[std::size_t(patch)].low.x() == doctest::Approx((20 - 39.5) * 1.5 / 500.0));
  CHECK(segments[std::size_t(patch)].high.x() == doctest::Approx((49 - 39.5) * 1.5 / 500.0));
  // Without the widening the ramp's 2 cm steps split it into its 20 columns.
  CHECK(bt::segmentDepth(depth, points, 0.01f, bt::NoiseScale(bt::DepthNoise(), 500.0), labels).size() == 2 + 20);
}

TEST_CASE("first view hull: the object's own surface is inside, points in front or beside it are not") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 1;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const synth::SyntheticFrame f = scene.frame(0);
  const bt::RgbdFrame frame = bt::makeFrame("0", f.color, f.depth, f.mask, camera);
  const bt::FirstViewHull hull(frame, camera, f.T_cam_obj, 5, 0.015f);
  const bt::SE3d T_obj_cam = f.T_cam_obj.inverse();
  // The mesh's surface points (object frame), all of them, front and back: every one is inside,
  // since the object lies behind its visible surface by less than its extent.
  const auto surface = scene.objectMesh().sampleSurface(500, 3);
  int inside = 0;
  for (const auto& p : surface) inside += hull.contains(p.cast<double>());
  CHECK(inside >= 490);  // a few samples project onto depth dropouts' neighbours at the rim
  // The visible surface is inside; moved 5 cm towards the camera, or behind it by more than the
  // extent, or sideways off the silhouette, it is outside.
  int visible = 0, in_front = 0, far_behind = 0, beside = 0, count = 0;
  for (int v = 0; v < frame.mask.rows; v += 2) {
    for (int u = 0; u < frame.mask.cols; u += 2) {
      const cv::Vec3f& x = frame.points.at<cv::Vec3f>(v, u);
      if (!frame.mask.at<uchar>(v, u) || x[2] <= 0.0f) continue;
      const Eigen::Vector3d c(x[0], x[1], x[2]), ray = c.normalized();
      ++count;
      visible += hull.contains(T_obj_cam * c);
      in_front += hull.contains(T_obj_cam * (c - 0.05 * ray));
      far_behind += hull.contains(T_obj_cam * (c + (hull.extent() + 0.05) / ray.z() * ray));
      beside += hull.contains(T_obj_cam * (c + Eigen::Vector3d(0.5, 0.0, 0.0)));
    }
  }
  REQUIRE(count > 1000);
  CHECK(visible == count);
  CHECK(in_front == 0);
  CHECK(far_behind == 0);
  CHECK(beside == 0);
  // The box is 0.10 x 0.07 x 0.16 m (diagonal d = 0.201 m); the extent is the camera-axis bounding
  // box of what one view sees: longer than the box's longest edge, shorter than sqrt(3) d.
  CHECK(hull.extent() > 0.16f);
  CHECK(hull.extent() < 0.348f);
}

TEST_CASE("propagated mask under the true pose matches the renderer's mask where there is depth") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 20;
  settings.speed = 2.0;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const int step = 4;
  const synth::SyntheticFrame f0 = scene.frame(0);
  const bt::RgbdFrame first = bt::makeFrame("0", f0.color, f0.depth, f0.mask, camera);
  bt::PropagatedMasks masks;
  masks.start(first, camera, f0.T_cam_obj, step);
  const bt::Keyframe seen = bt::makeKeyframe(0, first, first.mask, {}, f0.T_cam_obj, camera, step);
  const bt::KeyframePool no_keyframes(2);
  const bt::ObservedObject object({seen.surface.points, f0.T_cam_obj}, no_keyframes, 15);
  for (const int i : {1, 10, 19}) {  // up to ~30 degrees of rotation from the only view
    CAPTURE(i);
    const synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, cv::Mat(), camera);
    const cv::Mat mask = masks.mask(frame, object, f.T_cam_obj);
    // Pixels without depth after filtering cannot be told apart, and the tracker has no use for them.
    const cv::Mat truth = f.mask & (frame.depth > 0.0f);
    const double precision = double(cv::countNonZero(mask & truth)) / std::max(1, cv::countNonZero(mask));
    const double recall = double(cv::countNonZero(mask & truth)) / cv::countNonZero(truth);
    MESSAGE("frame " << i << ": precision " << precision << ", recall " << recall << ", IoU " << bt::maskIoU(mask, truth));
    CHECK(precision >= 0.97);
    CHECK(recall >= (i == 1 ? 0.95 : 0.8));  // surface turning into view is reached by growth only
    // The search region around the previous frame's pose holds the whole object.
    const cv::Mat region = masks.searchRegion(frame, object, scene.frame(i - 1).T_cam_obj);
    CHECK(cv::countNonZero(truth & ~region) == 0);
  }
  // Nothing where the object is not: the same pose in a frame without the object.
  const bt::RgbdFrame empty = bt::makeFrame("wall", f0.color, cv::Mat(f0.depth.size(), CV_32FC1, cv::Scalar(3.0f)),
                                            cv::Mat(), camera);
  CHECK(cv::countNonZero(masks.mask(empty, object, f0.T_cam_obj)) == 0);
}

TEST_CASE("propagated masks refuse a first mask they cannot follow, and use before start") {
  const bt::PinholeCameraf camera{500.0f, 500.0f, 39.5f, 29.5f};
  cv::Mat depth(60, 80, CV_32FC1, cv::Scalar(1.0f));
  depth(cv::Rect(10, 10, 20, 20)).setTo(0.0f);
  cv::Mat mask(60, 80, CV_8UC1, cv::Scalar(0));
  const cv::Mat color(60, 80, CV_8UC3, cv::Scalar::all(128));
  bt::PropagatedMasks masks;
  const auto problem = [&](const cv::Mat& m) -> std::string {
    try {
      masks.start(bt::makeFrame("first", color, depth, m, camera), camera, bt::SE3d(), 4);
    } catch (const bt::InputError& error) {
      CHECK(error.source() == "frame first");
      return error.problem();
    }
    return "";
  };
  CHECK(problem(mask).find("non-empty mask") != std::string::npos);
  mask(cv::Rect(12, 12, 10, 10)).setTo(255);  // only where the depth is invalid
  CHECK(problem(mask).find("no valid depth under the first mask") != std::string::npos);
  const bt::RgbdFrame later = bt::makeFrame("later", color, depth, cv::Mat(), camera);
  const bt::KeyframePool no_keyframes(2);
  CHECK_THROWS_AS(masks.mask(later, bt::ObservedObject({}, no_keyframes, 15), bt::SE3d()), bt::InputError);
}
