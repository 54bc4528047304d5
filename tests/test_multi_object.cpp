// Several objects in one camera: the synthetic scene with two and three objects (their masks,
// poses and occlusion against the renderer), the sequence layouts with a folder per object and
// with label images, and MultiObjectTracker against one tracker per object run alone
// (bit-identical) and against the exact ground truth.
#include <doctest/doctest.h>

#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "bundletrack/tracking/multi_object_tracker.hpp"
#include "temp_dir.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

namespace {

synth::SyntheticSequenceSettings sceneOf(int objects, int frames) {
  synth::SyntheticSequenceSettings settings;
  settings.objects = objects;
  settings.frames = frames;
  return settings;
}

/// Points of object `k`'s surface (object frame) hidden in frame i behind a surface of object
/// `front`: their pixel shows `front`, at least 1 cm nearer than the point.
int hiddenBehind(const synth::SyntheticScene& scene, int i, int k, int front) {
  const synth::RenderBuffers clean = scene.renderClean(i);
  const bt::SE3d T = scene.T_cam_obj(i, k);
  const auto& camera = scene.settings().camera;
  int hidden = 0;
  for (const Eigen::Vector3f& q : scene.objectMesh(k).sampleSurface(2000, 5)) {
    const Eigen::Vector3d p = T * q.cast<double>();
    const Eigen::Vector2d uv = camera.project(p);
    const int u = int(std::lround(uv.x())), v = int(std::lround(uv.y()));
    if (u < 0 || v < 0 || u >= clean.label.cols || v >= clean.label.rows) continue;
    hidden += clean.label.at<int>(v, u) == synth::SyntheticScene::objectLabel(front) &&
              clean.depth.at<float>(v, u) < p.z() - 0.01;
  }
  return hidden;
}

}  // namespace

TEST_CASE("synthetic scene of three objects: own shapes, masks where each is seen, occluding each other") {
  const synth::SyntheticScene scene(sceneOf(3, 150));
  REQUIRE(scene.objectCount() == 3);
  CHECK(scene.objectName(0) == "box");
  CHECK(scene.objectName(1) == "cylinder");
  CHECK(scene.objectName(2) == "mug");
  int second_in_front = 0, third_behind = 0;
  for (int i = 0; i < 150; i += 5) {
    const synth::SyntheticFrame f = scene.frame(i);
    REQUIRE(f.others.size() == 2);
    const synth::RenderBuffers clean = scene.renderClean(i);
    CHECK(cv::countNonZero(f.mask) > 500);
    for (int k = 1; k < 3; ++k) {
      const synth::ObjectView& view = f.others[std::size_t(k - 1)];
      // The mask is exactly the pixels the renderer shows the object at, and it is never empty.
      const cv::Mat expected = clean.label == synth::SyntheticScene::objectLabel(k);
      CHECK(cv::norm(view.mask, expected, cv::NORM_INF) == 0.0);
      CHECK(cv::countNonZero(view.mask & f.mask) == 0);
      CHECK(cv::countNonZero(view.mask) > 200);
      CHECK((view.T_cam_obj.matrix() - scene.T_cam_obj(i, k).matrix()).cwiseAbs().maxCoeff() == 0.0);
    }
    second_in_front += hiddenBehind(scene, i, 0, 1) > 20;
    third_behind += hiddenBehind(scene, i, 2, 0) > 20;
  }
  MESSAGE("frames (of 30) with the first object partly behind the second: ", second_in_front,
          ", with the third partly behind the first: ", third_behind);
  // The second object passes in front of the first, the first in front of the third, in some frames only.
  CHECK(second_in_front >= 3);
  CHECK(second_in_front <= 27);
  CHECK(third_behind >= 3);
  CHECK(third_behind <= 27);
  CHECK_THROWS_AS(synth::SyntheticScene(sceneOf(4, 10)), bt::InputError);
}

TEST_CASE("sequence with a folder of masks per object: objects, masks, poses and models of each") {
  const TempDir dir("multi_layout");
  const synth::SyntheticSequenceSettings settings = sceneOf(2, 3);
  synth::writeSyntheticSequence(dir.path(), settings);
  const synth::SyntheticScene scene(settings);
  const bt::io::RgbdSequence sequence(dir.path());
  REQUIRE(sequence.objects() == std::vector<std::string>{"box", "cylinder"});
  const synth::SyntheticFrame f = scene.frame(2);
  CHECK(cv::norm(*sequence.mask(2, "box"), f.mask, cv::NORM_INF) == 0.0);
  CHECK(cv::norm(*sequence.mask(2, "cylinder"), f.others[0].mask, cv::NORM_INF) == 0.0);
  CHECK(!sequence.mask(2));  // no mask of "the" object
  CHECK(bt::translationError(sequence.groundTruthPose(2, "cylinder"), f.others[0].T_cam_obj) < 1e-9);
  CHECK(sequence.hasModel("cylinder"));
  CHECK(!sequence.hasModel());
  CHECK(sequence.modelPoints("cylinder").size() == std::size_t(settings.model_points));
  // A sequence of one object has no object folders.
  const TempDir single("single_layout");
  synth::writeSyntheticSequence(single.path(), sceneOf(1, 2));
  CHECK(bt::io::RgbdSequence(single.path()).objects().empty());
  CHECK_THROWS_AS(synth::writeSyntheticSequence(single.path() / "labels", sceneOf(1, 2), bt::io::Layout::YcbInEoat,
                                                synth::MaskFiles::LabelImages),
                  bt::InputError);
}

TEST_CASE("sequence with label images: each object's masks are the renderer's") {
  const TempDir dir("label_layout");
  const synth::SyntheticSequenceSettings settings = sceneOf(3, 3);
  synth::writeSyntheticSequence(dir.path(), settings, bt::io::Layout::YcbInEoat, synth::MaskFiles::LabelImages);
  const synth::SyntheticScene scene(settings);
  const bt::io::RgbdSequence sequence(dir.path());
  REQUIRE(sequence.objects() == std::vector<std::string>{"box", "cylinder", "mug"});
  CHECK(sequence.objectList() == dir.path() / "labels" / "objects.txt");
  CHECK(sequence.maskPath(1, "mug") == dir.path() / "labels" / "000001.png");
  for (int i = 0; i < 3; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    const std::vector<std::optional<cv::Mat>> masks = sequence.masks(std::size_t(i));
    REQUIRE(masks.size() == 3);
    for (std::size_t k = 0; k < 3; ++k) {
      const cv::Mat& truth = k == 0 ? f.mask : f.others[k - 1].mask;
      REQUIRE(masks[k]);
      CHECK(cv::countNonZero(truth) > 0);
      CHECK(cv::norm(*masks[k], truth, cv::NORM_INF) == 0.0);
      CHECK(cv::norm(*sequence.mask(std::size_t(i), sequence.objects()[k]), truth, cv::NORM_INF) == 0.0);
    }
  }
  CHECK(!sequence.mask(0));  // no mask of "the" object
  CHECK(!sequence.read(0).mask.data);
  CHECK(bt::translationError(sequence.groundTruthPose(2, "mug"), scene.frame(2).others[1].T_cam_obj) < 1e-9);
  // A frame without its label image: no object has a mask there.
  std::filesystem::remove(dir.path() / "labels" / "000002.png");
  for (const std::optional<cv::Mat>& mask : sequence.masks(2)) CHECK(!mask);
  // A label image of three channels.
  cv::imwrite((dir.path() / "labels" / "000002.png").string(), cv::Mat(scene.frame(0).mask.size(), CV_8UC3, cv::Scalar::all(1)));
  CHECK_THROWS_WITH_AS(sequence.masks(2), doctest::Contains("a label image must have one channel of 8 or 16 bits"),
                       bt::InputError);
  // Masks in both layouts: which would be meant?
  std::filesystem::create_directories(dir.path() / "masks" / "box");
  CHECK_THROWS_WITH_AS(bt::io::RgbdSequence(dir.path()), doctest::Contains("both label images and masks/"), bt::InputError);
}

TEST_CASE("labels/objects.txt: each line a label and a name, every mistake named with its line") {
  const auto parse = [](const std::string& text) {
    std::istringstream in(text);
    return bt::io::parseLabelNames(in, "objects.txt");
  };
  const auto objects = parse("# label object\n1 box\n\n  7 the_mug.2  # comment\n65535 last-one\n");
  REQUIRE(objects.size() == 3);
  CHECK(objects[1] == std::pair<int, std::string>{7, "the_mug.2"});
  CHECK(objects[2].first == 65535);
  const auto refused = [&](const std::string& text, const char* message) {
    CHECK_THROWS_WITH_AS(parse(text), doctest::Contains(message), bt::InputError);
  };
  refused("", "no object listed");
  refused("# nothing\n", "no object listed");
  refused("1 box\n0 cup\n", "line 2: label '0' is not an integer from 1 to 65535");
  refused("65536 box\n", "line 1: label '65536'");
  refused("1.5 box\n", "line 1: label '1.5'");
  refused("box 1\n", "line 1: label 'box'");
  refused("1\n", "line 1: expected '<label> <name>'");
  refused("1 box cup\n", "line 1: expected '<label> <name>'");
  refused("1 box\n1 cup\n", "line 2: label 1 is given twice");
  refused("1 box\n2 box\n", "line 2: object 'box' is given twice");
  refused("1 ../x\n", "line 1: object name '../x' may hold only");
  refused("1 ..\n", "line 1: object name '..'");
}

TEST_CASE("MultiObjectTracker: each object tracked as alone, bit for bit, one of them starting later") {
  constexpr int kFrames = 30, kLateStart = 10;
  const synth::SyntheticScene scene(sceneOf(2, kFrames));
  const auto camera = scene.settings().camera.cast<float>();
  const bt::Config config;
  bt::MultiObjectTracker together(2, [&] { return bt::makeTracker(config, camera); });
  std::unique_ptr<bt::AnyTracker> alone[2] = {bt::makeTracker(config, camera), bt::makeTracker(config, camera)};
  std::vector<bt::SE3d> truth[2], estimate[2];
  for (int i = 0; i < kFrames; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    // The cylinder's masks are empty before kLateStart: it has not come into the scene for the tracker yet.
    const cv::Mat cylinder_mask = i < kLateStart ? cv::Mat::zeros(f.mask.size(), CV_8UC1) : f.others[0].mask;
    const bt::MultiObjectTracker::ObjectMasks masks = {f.mask, cylinder_mask};
    const cv::Rect region = together.regionOfInterest(f.color.size(), masks);
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, cv::Mat(), camera, {}, region);
    const std::vector<bt::SE3d> start = {f.T_cam_obj, f.others[0].T_cam_obj};
    const std::vector<std::optional<bt::TrackResult>> results = together.track(frame, masks, start);
    REQUIRE(results.size() == 2);
    CHECK(together.started(1) == (i >= kLateStart));
    CHECK(results[1].has_value() == (i >= kLateStart));
    for (int k = 0; k < 2; ++k) {
      if (k == 1 && i < kLateStart) continue;
      // Alone: the object's own mask, the frame preprocessed only where its tracker asks.
      const cv::Mat own = k == 0 ? f.mask : f.others[0].mask;
      const cv::Rect own_region = alone[k]->regionOfInterest(f.color.size(), own);
      const bt::RgbdFrame own_frame = bt::makeFrame(std::to_string(i), f.color, f.depth, own, camera, {}, own_region);
      const bool first = k == 0 ? i == 0 : i == kLateStart;
      const bt::TrackResult single = first ? alone[k]->initialize(own_frame, start[std::size_t(k)]) : alone[k]->track(own_frame);
      REQUIRE(results[std::size_t(k)].has_value());
      const bt::TrackResult& shared = *results[std::size_t(k)];
      CHECK(shared.status == single.status);
      CHECK((shared.T_cam_obj.matrix() - single.T_cam_obj.matrix()).cwiseAbs().maxCoeff() == 0.0);
      truth[k].push_back(k == 0 ? f.T_cam_obj : f.others[0].T_cam_obj);
      estimate[k].push_back(shared.T_cam_obj);
    }
  }
  for (int k = 0; k < 2; ++k) {
    const bt::SequenceScore score = bt::scoreSequence(scene.objectMesh(k).sampleSurface(1000, 2), truth[k], estimate[k]);
    CAPTURE(k);
    CHECK(score.adds_auc > 95.0);
  }
  CHECK_THROWS_AS(together.track(bt::RgbdFrame(), {cv::Mat()}, {bt::SE3d(), bt::SE3d()}), bt::InputError);
  CHECK_THROWS_AS(together.regionOfInterest({640, 480}, {}), bt::InputError);
}
