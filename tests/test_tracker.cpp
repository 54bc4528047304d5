// The full tracker against exact synthetic ground truth and against the coarse tracker; trackers
// composed at run time (makeTracker) against the same ones composed at compile time; a residual
// term from outside the library in a tracker's energy. (One translation unit: the trackers'
// instantiations are compiled once for all of them.)
#include <doctest/doctest.h>

#include <algorithm>
#include <iterator>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include "bundletrack/default_tracker.hpp"
#include "bundletrack/eval/mask_iou.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/graph/object_model.hpp"
#include "bundletrack/masks/propagated_masks.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/solvers/dense_ldlt.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "cost_gradient.hpp"
#include "feature_point_to_plane.hpp"

namespace bt = bundletrack;
namespace synth = bundletrack::synth;

namespace {

struct Run {
  bt::SequenceScore score;
  int lost = 0, tracked = 0, by_surface = 0, followed = 0;
  double mean_mask_iou = 0.0;  ///< against the renderer's mask where the filtered depth is valid
  std::vector<bt::SE3d> poses;
  std::vector<double> stabilities;  ///< of the frames that report one
};

/// Tracks the scene; with `first_mask_only` every frame after the first comes without its mask.
/// Frames are made with `frame_settings` (the sensor's noise model among them); with
/// `region_only`, preprocessed only inside the tracker's regionOfInterest.
template <typename Tracker>
Run track(Tracker&& tracker, const synth::SyntheticScene& scene, const std::vector<Eigen::Vector3f>& model,
          bool first_mask_only = false, const bt::FrameSettings& frame_settings = {}, bool region_only = false) {
  std::vector<bt::SE3d> truth, estimate;
  Run run;
  const auto camera = scene.settings().camera.cast<float>();
  for (int i = 0; i < scene.settings().frames; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    const cv::Mat mask = first_mask_only && i > 0 ? cv::Mat() : f.mask;
    const cv::Rect region = region_only ? tracker.regionOfInterest(f.color.size(), mask) : cv::Rect();
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, mask, camera, frame_settings, region);
    const bt::TrackResult result = i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame);
    run.lost += result.status == bt::TrackStatus::Lost;
    run.tracked += result.status == bt::TrackStatus::Tracked;
    run.by_surface += result.surface_only;
    run.followed += result.followed > 0;
    if (result.stability) run.stabilities.push_back(*result.stability);
    if (!result.mask.empty()) run.mean_mask_iou += bt::maskIoU(result.mask, f.mask & (frame.depth > 0.0f));
    truth.push_back(f.T_cam_obj);
    estimate.push_back(result.T_cam_obj);
  }
  run.mean_mask_iou /= scene.settings().frames;
  run.score = bt::scoreSequence(model, truth, estimate);
  run.poses = std::move(estimate);
  return run;
}

double largestDifference(const Run& a, const Run& b) {
  REQUIRE(a.poses.size() == b.poses.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < a.poses.size(); ++i)
    largest = std::max(largest, (a.poses[i].matrix() - b.poses[i].matrix()).cwiseAbs().maxCoeff());
  return largest;
}

/// The first `frames` frames of the default synthetic sequence (hand-held box).
struct ShortScene {
  explicit ShortScene(int frames) : scene(withFrames(frames)), model(scene.objectMesh().sampleSurface(1000, 1)) {}
  static synth::SyntheticSequenceSettings withFrames(int frames) {
    synth::SyntheticSequenceSettings settings;
    settings.frames = frames;
    return settings;
  }
  bt::PinholeCameraf camera() const { return scene.settings().camera.cast<float>(); }

  synth::SyntheticScene scene;
  std::vector<Eigen::Vector3f> model;
};

using PropagatedTracker =
    bt::Tracker<bt::DefaultEnergy, bt::PCG, bt::SiftFeatures, bt::PropagatedMasks, bt::Ransac, bt::SurfaceAgreement>;

}  // namespace

TEST_CASE("full tracker on a synthetic hand-held box: ADD-S AUC >= 95 and less drift than the coarse tracker" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 60;
  settings.speed = 2.0;  // the box turns by 160 degrees over the 60 frames
  const synth::SyntheticScene scene(settings);
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  const Run full = track(bt::DefaultTracker(settings.camera.cast<float>()), scene, model);
  const Run coarse = track(bt::DefaultCoarseTracker(), scene, model);
  MESSAGE("full:   ADD " << full.score.add_auc << " ADD-S " << full.score.adds_auc << " final ADD "
                         << full.score.final_add_cm << " cm, tracked " << full.tracked);
  MESSAGE("coarse: ADD " << coarse.score.add_auc << " ADD-S " << coarse.score.adds_auc << " final ADD "
                         << coarse.score.final_add_cm << " cm");
  CHECK(full.lost == 0);
  CHECK(full.tracked == settings.frames);
  CHECK(full.score.adds_auc >= 95.0);
  CHECK(full.score.add_auc >= 95.0);
  CHECK(full.score.final_add_cm < coarse.score.final_add_cm);
}

TEST_CASE("brightness keeps a small textured mug's turn at 2 m where its surface cannot" * doctest::test_suite("end_to_end")) {
  // The stress matrix's A_mug_2m_textured: a 10 cm mug 2 m away fills about 20 x 20 pixels, and
  // structured-light depth there (7 mm spread, 13 mm disparity steps) does not see its curvature
  // nor much of its handle: the turn about its axis is left to the texture. Without it the turn
  // is a random walk whose end differs from one noise seed to the next, so the mean over five
  // seeds (textures and sensor noise) is compared: brightness turns less on four of them and
  // further on one (seed 4: 27.9 against 20.3 degrees), 12.3 against 22.1 degrees in the mean.
  // Three seeds left the means within a few hundredths of a degree of the bound, which such a
  // walk does not support. The silhouette term is off in both: the handle's outline holds the
  // turn too, and this test weighs brightness alone.
  bt::Config with;
  with.silhouette_weight = 0.0;
  bt::Config without = with;
  without.photometric_weight = 0.0;
  constexpr unsigned kSeeds[] = {2, 3, 4, 5, 6};
  constexpr double kRuns = double(std::size(kSeeds));
  double surface_deg = 0.0, brightness_deg = 0.0;
  for (const unsigned seed : kSeeds) {
    synth::SyntheticSequenceSettings settings;
    settings.shape = synth::Shape::Mug;
    settings.size = 0.10;
    settings.distance = 2.0;
    settings.frames = 60;
    settings.seed = seed;
    const synth::SyntheticScene scene(settings);
    const auto model = scene.objectMesh().sampleSurface(1000, 1);
    const Run surface = track(*bt::makeTracker(without, settings.camera.cast<float>()), scene, model);
    const Run brightness = track(*bt::makeTracker(with, settings.camera.cast<float>()), scene, model);
    MESSAGE("seed " << seed << ": mean rotation error without the photometric term " << surface.score.rotation_error_deg
            << " deg, with it " << brightness.score.rotation_error_deg << " deg; ADD-S " << brightness.score.adds_auc);
    CHECK(brightness.lost == 0);
    CHECK(brightness.score.adds_auc >= 95.0);
    surface_deg += surface.score.rotation_error_deg / kRuns;
    brightness_deg += brightness.score.rotation_error_deg / kRuns;
  }
  CHECK(brightness_deg < 0.6 * surface_deg);
}

TEST_CASE("a far mug's outline holds its handle where nothing behind it is within the sensor's range" *
          doctest::test_suite("end_to_end")) {
  // The stress matrix's 3 m mug with a perfect sensor: a 13 px mug whose exact mask shows its handle
  // 3 px beside the body, before a wall 1 m behind it at the synthetic sensor's 4 m limit, so no
  // reading surrounds it. The silhouette term sees past that background (SilhouetteImage::depth);
  // when it counted only points with a reading behind them, the handle left the mask from frame 45
  // on and the mean rotation error over these 60 frames was 18 degrees (5.6 now; 100 frames: 71
  // degrees against 25).
  synth::SyntheticSequenceSettings settings;
  settings.shape = synth::Shape::Mug;
  settings.size = 0.10;
  settings.distance = 3.0;
  settings.frames = 60;
  settings.sensor = synth::SensorSettings::perfect();
  const synth::SyntheticScene scene(settings);
  const Run run = track(*bt::makeTracker(bt::Config{}, settings.camera.cast<float>()), scene,
                        scene.objectMesh().sampleSurface(1000, 1));
  MESSAGE("mean rotation error " << run.score.rotation_error_deg << " deg, ADD " << run.score.add_auc);
  CHECK(run.lost == 0);
  CHECK(run.score.rotation_error_deg < 10.0);
}

namespace {

/// A textureless object of `size` metres `distance` metres away, as the stress matrix's far cells.
synth::SyntheticSequenceSettings texturelessAt(synth::Shape shape, double size, double distance, int frames) {
  synth::SyntheticSequenceSettings settings;
  settings.shape = shape;
  settings.size = size;
  settings.distance = distance;
  settings.textureless = true;
  settings.frames = frames;
  return settings;
}

/// The stress matrix's textureless 20 cm box 3 m away (60 frames), its masks off the outline by
/// `error` (3 px), tracked by the default tracker without and with the silhouette term.
struct OutlineRuns {
  Run surface, outline;
};
OutlineRuns texturelessBoxAt3m(synth::MaskError error) {
  synth::SyntheticSequenceSettings settings = texturelessAt(synth::Shape::Box, 0.20, 3.0, 60);
  settings.mask_error = error;
  settings.mask_error_px = 3;
  const synth::SyntheticScene scene(settings);
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  bt::Config without;
  without.silhouette_weight = 0.0;
  return {track(*bt::makeTracker(without, settings.camera.cast<float>()), scene, model),
          track(*bt::makeTracker(bt::Config(), settings.camera.cast<float>()), scene, model)};
}

}  // namespace

TEST_CASE("the outline holds a textureless box at 3 m where its surface lets it slide" * doctest::test_suite("end_to_end")) {
  // The stress matrix's A_box_3m_textureless: a 20 cm box 3 m away shows its front and top faces,
  // whose common direction (along their edge) neither surface constrains, and one flat colour;
  // structured-light depth there has a 14 mm spread. Without the silhouette term the pose slides
  // along that edge by 1-2 cm from frame to frame; the outline of the given masks pins it.
  const auto [surface, outline] = texturelessBoxAt3m(synth::MaskError::None);
  MESSAGE("without the silhouette term: ADD " << surface.score.add_auc << ", mean translation error "
          << surface.score.translation_error_cm << " cm; with it: ADD " << outline.score.add_auc << ", "
          << outline.score.translation_error_cm << " cm");
  CHECK(outline.lost == 0);
  CHECK(outline.score.adds_auc >= 95.0);
  CHECK(outline.score.translation_error_cm < 0.6 * surface.score.translation_error_cm);
}

TEST_CASE("masks 3 px off the outline do not pull the textureless box at 3 m: as accurate as without the outline" * doctest::test_suite("end_to_end")) {
  // Real masks err by a few pixels (a segmentation's boundary, depth registered to colour). A mask
  // grown onto the wall behind (dilated) gives the object points that move with the wall, a mask
  // moved sideways (shifted) does that on one side and misses the object's rim on the other; at
  // 3 m the 20 cm box is 40 px wide. The term counts only the object's points (not those behind a
  // depth edge of the mask) and only where the frame saw past them (not a rim the mask misses), so
  // its pose is as good as the surface's alone; counting them turned the box by 27 / 20 degrees.
  for (const synth::MaskError error : {synth::MaskError::Dilated, synth::MaskError::Shifted}) {
    const auto [surface, outline] = texturelessBoxAt3m(error);
    MESSAGE((error == synth::MaskError::Dilated ? "dilated" : "shifted") << " masks: without the silhouette term ADD-S "
            << surface.score.adds_auc << ", rotation error " << surface.score.rotation_error_deg << " deg; with it "
            << outline.score.adds_auc << ", " << outline.score.rotation_error_deg << " deg");
    CHECK(outline.lost == 0);
    CHECK(outline.score.adds_auc >= surface.score.adds_auc - 0.5);
    CHECK(outline.score.rotation_error_deg <= 1.2 * surface.score.rotation_error_deg);
  }
}

TEST_CASE("keyframes carry intensity and silhouette images where a term of the energy reads them and silhouettes only of given masks") {
  using Features = bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>;
  CHECK(bt::DefaultEnergy().readsImages());
  CHECK_FALSE(bt::Energy<Features>().readsImages());
  CHECK(bt::DefaultEnergy().readsSilhouettes());
  bt::DefaultEnergy without;
  std::get<2>(without.terms).weight = 0.0;
  CHECK_FALSE(without.readsImages());
  CHECK(without.readsSilhouettes());
  std::get<3>(without.terms).weight = 0.0;
  CHECK_FALSE(without.readsSilhouettes());
  synth::SyntheticSequenceSettings settings;
  settings.frames = 2;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const synth::SyntheticFrame f = scene.frame(0);
  const bt::RgbdFrame frame = bt::makeFrame("0", f.color, f.depth, f.mask, camera);
  bt::DefaultTracker with_term(camera), without_term(camera, {}, without);
  with_term.initialize(frame, f.T_cam_obj);
  without_term.initialize(frame, f.T_cam_obj);
  const bt::Keyframe& first = with_term.keyframes()[0];
  CHECK_FALSE(first.image.empty());
  CHECK(first.image.cells.size() > first.surface.cells.size() / 2);
  CHECK_FALSE(first.silhouette.empty());
  CHECK(first.silhouette.points.size() >= first.surface.cells.size());  // normals or not
  CHECK(without_term.keyframes()[0].image.empty());
  CHECK(without_term.keyframes()[0].silhouette.empty());
  CHECK(without_term.keyframes()[0].surface.cells.size() == first.surface.cells.size());
  // Propagated masks end at the object's depth edges (PropagatedMasks::kOutline): silhouettes too.
  PropagatedTracker propagated(camera);
  propagated.initialize(frame, f.T_cam_obj);
  CHECK_FALSE(propagated.keyframes()[0].image.empty());
  CHECK_FALSE(propagated.keyframes()[0].silhouette.empty());
}

TEST_CASE("from the first mask alone: propagated masks track the hand-held box as well as given masks" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 60;
  settings.speed = 2.0;
  const synth::SyntheticScene scene(settings);
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  const auto camera = settings.camera.cast<float>();
  const Run given = track(bt::DefaultTracker(camera), scene, model);
  const Run propagated = track(PropagatedTracker(camera), scene, model, true);
  MESSAGE("given masks: ADD-S " << given.score.adds_auc << "; propagated: ADD-S " << propagated.score.adds_auc
                                << ", mean mask IoU " << propagated.mean_mask_iou);
  CHECK(propagated.lost == 0);
  CHECK(propagated.score.adds_auc >= 95.0);
  CHECK(propagated.score.adds_auc >= given.score.adds_auc - 1.0);
  CHECK(propagated.mean_mask_iou >= 0.8);
}

TEST_CASE("from the first mask alone: the propagated mask's outline keeps a far textureless chair from sliding" * doctest::test_suite("end_to_end")) {
  // A 0.7 m chair without texture 3 m away, seen mostly on its seat and back: planes the surface
  // lets slide in, features too few to hold them. Without the outline of its propagated masks the
  // pose slid sideways by up to 5.6 cm (seed 2: mean 2.5 cm over 30 frames; seeds 1 and 3: 0.4 cm
  // each), with it every seed stays at 0.23-0.33 cm. Bounds: 0.5 cm per seed, about a third of one
  // structured-light reading's spread there (1.4 cm), and half the error without it in the mean.
  constexpr unsigned kSeeds[] = {1, 2, 3};
  bt::Config with;
  with.masks = "propagated";
  bt::Config without = with;
  without.silhouette_weight = 0.0;
  double with_cm = 0.0, without_cm = 0.0;
  for (const unsigned seed : kSeeds) {
    synth::SyntheticSequenceSettings settings = texturelessAt(synth::Shape::Chair, 0.70, 3.0, 30);
    settings.seed = seed;
    const synth::SyntheticScene scene(settings);
    const auto model = scene.objectMesh().sampleSurface(1000, 1);
    const auto camera = settings.camera.cast<float>();
    const Run outline = track(*bt::makeTracker(with, camera), scene, model, true);
    const Run surface = track(*bt::makeTracker(without, camera), scene, model, true);
    MESSAGE("seed " << seed << ": mean translation error with the outline " << outline.score.translation_error_cm
            << " cm (ADD " << outline.score.add_auc << "), without " << surface.score.translation_error_cm << " cm");
    CHECK(outline.lost == 0);
    CHECK(outline.score.translation_error_cm < 0.5);
    CHECK(outline.score.add_auc >= 95.0);
    with_cm += outline.score.translation_error_cm;
    without_cm += surface.score.translation_error_cm;
  }
  CHECK(with_cm < 0.5 * without_cm);
}

TEST_CASE("from the first mask alone: a mug on the table under an orbiting camera keeps the table out of its mask" * doctest::test_suite("end_to_end")) {
  // A textureless 10 cm mug standing on the table 2 m away under active stereo (1 cm spread): the
  // table around its foot lies within the depth noise of the mug's lowest centimetres, and a camera
  // moving round the mug keeps the table still in the mug's frame, so table pixels that join the
  // mask once are rendered with the object and join again. With the support plane, where depth
  // cannot tell, the first mask's colours against those around it decide.
  synth::SyntheticSequenceSettings settings = texturelessAt(synth::Shape::Mug, 0.10, 2.0, 40);
  settings.motion = synth::Motion::CameraOrbit;
  settings.sensor.depth_noise = bt::DepthNoise::activeStereo();
  bt::FrameSettings frame_settings;
  frame_settings.sensor = settings.sensor.depth_noise;
  bt::Config with;
  with.masks = "propagated";
  bt::Config without = with;
  without.propagated_masks.stop_at_support = false;
  const synth::SyntheticScene scene(settings);
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  const auto camera = settings.camera.cast<float>();
  const Run kept_off = track(*bt::makeTracker(with, camera), scene, model, true, frame_settings);
  const Run taken_in = track(*bt::makeTracker(without, camera), scene, model, true, frame_settings);
  MESSAGE("mean mask IoU with the support plane " << kept_off.mean_mask_iou << " (ADD-S " << kept_off.score.adds_auc
          << "), without " << taken_in.mean_mask_iou << " (ADD-S " << taken_in.score.adds_auc << ")");
  CHECK(kept_off.lost == 0);
  CHECK(kept_off.score.adds_auc >= 95.0);
  CHECK(kept_off.mean_mask_iou >= 0.7);
  CHECK(kept_off.mean_mask_iou >= taken_in.mean_mask_iou + 0.15);
}

TEST_CASE("feature-only and dense-only energies compose and track, and dense alone holds a textureless can") {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 30;
  settings.shape = synth::Shape::Cylinder;
  settings.textureless = true;
  const synth::SyntheticScene scene(settings);
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  // A can without texture: rotation about its axis is unobservable, so ADD-S is the measure.
  const Run full = track(bt::DefaultTracker(settings.camera.cast<float>()), scene, model);
  MESSAGE("textureless can: ADD-S " << full.score.adds_auc << ", lost " << full.lost);
  CHECK(full.score.adds_auc >= 90.0);
  using FeatureOnly = bt::Tracker<bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>>, bt::DenseLDLT,
                                  bt::SiftFeatures, bt::GivenMasks, bt::Ransac, bt::SurfaceAgreement>;
  synth::SyntheticSequenceSettings box = settings;
  box.shape = synth::Shape::Box;
  box.textureless = false;
  const synth::SyntheticScene box_scene(box);
  const Run features = track(FeatureOnly(box.camera.cast<float>()), box_scene, box_scene.objectMesh().sampleSurface(1000, 1));
  CHECK(features.score.adds_auc >= 95.0);
}

TEST_CASE("a frame's reported stability: a textured box is held in every direction, a textureless can's turn about its axis is not" * doctest::test_suite("end_to_end")) {
  // Nothing but the normals' noise holds a textureless can's turn about its axis (its surface,
  // outline and shading are the same at every turn), while the box's faces, outline and texture
  // hold every direction: its reported stability must be several times the can's.
  const auto median = [](std::vector<double> values) {
    REQUIRE(!values.empty());
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
    return values[values.size() / 2];
  };
  synth::SyntheticSequenceSettings settings;
  settings.frames = 20;
  const synth::SyntheticScene box(settings);
  settings.shape = synth::Shape::Cylinder;
  settings.textureless = true;
  const synth::SyntheticScene can(settings);
  const Run held = track(bt::DefaultTracker(settings.camera.cast<float>()), box, box.objectMesh().sampleSurface(1000, 1));
  const Run free = track(bt::DefaultTracker(settings.camera.cast<float>()), can, can.objectMesh().sampleSurface(1000, 1));
  CHECK(int(held.stabilities.size()) == held.tracked - 1);  // every graph-tracked frame but the first (no graph)
  CHECK(int(free.stabilities.size()) == free.tracked - 1);
  const double box_median = median(held.stabilities), can_median = median(free.stabilities);
  MESSAGE("median stability: box " << box_median << ", textureless can " << can_median);
  CHECK(box_median > 0.02);
  CHECK(can_median < box_median / 5.0);
}

TEST_CASE("keypoints on demand: frames the surface holds skip them and track as well as keypoints on every frame" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 40;
  settings.shape = synth::Shape::Chair;  // legs, seat and back: most views hold every direction
  settings.distance = 1.0;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  bt::TrackerSettings every_frame;
  every_frame.keypoints = bt::KeypointSchedule::EveryFrame;
  const Run every = track(bt::DefaultTracker(camera, every_frame), scene, model);
  const bt::TrackerSettings defaults;
  CHECK(defaults.keypoints == bt::KeypointSchedule::OnDemand);
  bt::TrackerSettings on_demand;
  bt::DefaultTracker tracker(camera, on_demand);
  const Run run = track(tracker, scene, model);
  MESSAGE("on demand: " << run.by_surface << " of " << settings.frames - 1 << " frames without keypoints, ADD-S "
                        << run.score.adds_auc << " (every frame: " << every.score.adds_auc << ")");
  CHECK(every.by_surface == 0);
  CHECK(run.lost == 0);
  CHECK(run.by_surface >= settings.frames / 5);
  // Issue 16's bar for a cheaper keypoint setting: within 0.5 ADD-S of the best.
  CHECK(run.score.adds_auc >= every.score.adds_auc - 0.5);
  for (std::size_t k = 0; k < tracker.keyframes().size(); ++k) CHECK(tracker.keyframes()[k].features.size() > 0);
  // A surface never stable enough: every frame falls back to keypoints and the attempt leaves
  // no trace (it stops before the graph is built).
  on_demand.min_surface_stability = 1.0;
  on_demand.follow_keypoints = false;
  const Run never = track(bt::DefaultTracker(camera, on_demand), scene, model);
  CHECK(never.by_surface == 0);
  CHECK(largestDifference(never, every) == 0.0);
}

TEST_CASE("keypoints followed by optical flow track a box the surface cannot hold as well as detected ones" * doctest::test_suite("end_to_end")) {
  const ShortScene box(40);  // a textured box, mostly one or two faces in view: its surface slides
  bt::TrackerSettings detect;
  detect.follow_keypoints = false;
  const Run detected = track(bt::DefaultTracker(box.camera(), detect), box.scene, box.model);
  CHECK(bt::TrackerSettings().follow_keypoints);
  bt::DefaultTracker tracker(box.camera());
  const Run run = track(tracker, box.scene, box.model);
  MESSAGE("followed on " << run.followed << " of 39 frames, ADD-S " << run.score.adds_auc << " (detected on every frame the "
                         << "surface cannot hold: " << detected.score.adds_auc << ")");
  CHECK(run.lost == 0);
  CHECK(run.followed >= 20);
  // Issue 16's bar for a cheaper keypoint setting: within 0.5 ADD-S of the best.
  CHECK(run.score.adds_auc >= detected.score.adds_auc - 0.5);
  // Keyframes detect their own keypoints (they are matched for later edges and re-acquisition).
  for (std::size_t k = 0; k < tracker.keyframes().size(); ++k) CHECK(tracker.keyframes()[k].features.size() > 50);
}

TEST_CASE("a textureless mug hidden by a passing arm is re-acquired by its surface and not lost for good" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 120;  // the arm crosses the mug around frame 60
  settings.shape = synth::Shape::Mug;
  settings.textureless = true;
  settings.occluder = true;
  settings.seed = 5;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  // Re-acquisition compared without the silhouette term, which holds part of the crossing itself.
  bt::DefaultEnergy without_outline;
  std::get<3>(without_outline.terms).weight = 0.0;
  const Run surface = track(bt::DefaultTracker(camera, {}, without_outline), scene, model);
  bt::TrackerSettings features_only;
  features_only.recovery_surface_candidates = 0;  // re-acquisition by features alone, as before
  const Run stuck = track(bt::DefaultTracker(camera, features_only, without_outline), scene, model);
  const Run outline = track(bt::DefaultTracker(camera), scene, model);
  MESSAGE("lost frames: " << surface.lost << " (features only: " << stuck.lost << "; default, with the silhouette term: "
                          << outline.lost << "), ADD-S " << surface.score.adds_auc << " (features only: "
                          << stuck.score.adds_auc << "; default: " << outline.score.adds_auc << ")");
  CHECK(stuck.lost >= 20);  // too few keypoints ever to pass 12 inliers again
  CHECK(surface.lost <= 10);
  CHECK(outline.lost <= 10);
  // Rotation about the mug's axis is barely observable without texture: ADD-S is the measure.
  CHECK(surface.score.adds_auc >= 90.0);
  CHECK(outline.score.adds_auc >= 90.0);
}

TEST_CASE("a textureless box 2.5 m from a structured-light camera is tracked with no frame lost" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 60;
  settings.distance = 2.5;  // sigma 9.6 mm and disparity steps of 17 mm on the box
  settings.textureless = true;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  const Run run = track(bt::DefaultTracker(camera), scene, model);
  // The same tracker told nothing of the noise: every tolerance stays as set for 1 m.
  bt::FrameSettings noiseless;
  noiseless.sensor = bt::DepthNoise();
  const Run fixed = track(bt::DefaultTracker(camera), scene, model, false, noiseless);
  MESSAGE("lost " << run.lost << " (fixed tolerances: " << fixed.lost << "), ADD-S " << run.score.adds_auc
                  << " (fixed: " << fixed.score.adds_auc << "), mean rotation error " << run.score.rotation_error_deg);
  CHECK(run.lost == 0);
  CHECK(fixed.lost >= 30);
  // ADD-S AUC over 0-10 cm: 85 is a mean error of ~1.5 cm, 1.5 sigma of one reading there.
  CHECK(run.score.adds_auc >= 85.0);
}

TEST_CASE("a 1280x720 depth camera 87 degrees wide (a RealSense D435's at 720p) tracks the box at 1 m as a 640x480 one does" *
          doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 40;
  settings.distance = 1.0;
  settings.sensor.depth_noise = bt::DepthNoise::activeStereo();
  bt::FrameSettings active_stereo;
  active_stereo.sensor = settings.sensor.depth_noise;
  const auto tracked = [&](const cv::Size& size, const bt::PinholeCamerad& camera) {
    synth::SyntheticSequenceSettings at = settings;
    at.image_size = size;
    at.camera = camera;
    const synth::SyntheticScene scene(at);
    return track(bt::DefaultTracker(camera.cast<float>()), scene, scene.objectMesh().sampleSurface(1000, 1), false, active_stereo);
  };
  // Every pixel tolerance of the tracker (windows, margins, the grid's largest step) was set on
  // 640x480 images 56 degrees wide; here the box covers about as many pixels (f 674 px against
  // 600), among three times as many pixels of background.
  const Run wide = tracked({1280, 720}, {674.0, 674.0, 639.5, 359.5});
  const Run narrow = tracked(settings.image_size, settings.camera);
  MESSAGE("1280x720, 87 degrees: ADD-S " << wide.score.adds_auc << ", lost " << wide.lost << ", mean rotation error "
                                         << wide.score.rotation_error_deg << "; 640x480, 56 degrees: ADD-S " << narrow.score.adds_auc
                                         << ", lost " << narrow.lost);
  CHECK(wide.lost == 0);
  // ADD-S AUC over 0-10 cm: 98 is a mean error of ~2 mm, a few readings' spread at 1 m.
  CHECK(wide.score.adds_auc >= 98.0);
  CHECK(wide.score.adds_auc >= narrow.score.adds_auc - 0.5);
}

TEST_CASE("after the object was out of view it is re-acquired with fewer than 12 keypoints per frame" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 80;
  settings.distance = 2.5;
  settings.hidden_start = 60;  // near the turning point of the motion, back at frame 70
  settings.hidden_frames = 10;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  bt::SiftSettings few;
  few.max_keypoints = 10;  // never the 12 inliers a feature re-acquisition needs
  struct Outcome {
    int first_recovered = -1;
    double worst_before = 0.0, worst_after = 0.0;  ///< rotation error (deg) of the poses reported good
    double worst_translation_after = 0.0;
  };
  const auto run = [&](const bt::TrackerSettings& tracking) {
    bt::DefaultTracker tracker(camera, tracking, bt::DefaultEnergy(), bt::PCG(), bt::SiftFeatures(few));
    Outcome out;
    int lost_while_gone = 0, most_keypoints = 0;
    for (int i = 0; i < settings.frames; ++i) {
      const synth::SyntheticFrame f = scene.frame(i);
      const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
      const bt::TrackResult r = i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame);
      most_keypoints = std::max(most_keypoints, r.keypoints);
      const bool gone = i >= settings.hidden_start && i < settings.hidden_start + settings.hidden_frames;
      if (gone) lost_while_gone += r.status == bt::TrackStatus::Lost;
      if (r.status == bt::TrackStatus::Lost) continue;
      const double error = bt::rotationErrorDeg(f.T_cam_obj, r.T_cam_obj);
      if (i < settings.hidden_start) {
        out.worst_before = std::max(out.worst_before, error);
        continue;
      }
      if (out.first_recovered < 0) out.first_recovered = i;
      out.worst_after = std::max(out.worst_after, error);
      out.worst_translation_after = std::max(out.worst_translation_after, bt::translationError(f.T_cam_obj, r.T_cam_obj));
    }
    MESSAGE("lost while gone " << lost_while_gone << ", first good frame " << out.first_recovered
                               << ", worst rotation error " << out.worst_before << " deg before, " << out.worst_after
                               << " after; translation after " << 100 * out.worst_translation_after << " cm; at most "
                               << most_keypoints << " keypoints");
    CHECK(most_keypoints < 12);
    CHECK(lost_while_gone == settings.hidden_frames);
    return out;
  };
  const Outcome surface = run(bt::TrackerSettings());
  CHECK(surface.first_recovered >= settings.hidden_start + settings.hidden_frames);
  CHECK(surface.first_recovered - (settings.hidden_start + settings.hidden_frames) < 3);
  // With 10 keypoints on a box 2.5 m away the track holds 3-8 degrees; the re-acquired poses are
  // no worse than 5 degrees beyond that (a wrong one -- the box turned by 90 degrees, or the
  // pose where it left, 10 frames of motion back -- is off by far more) and within 2 cm.
  CHECK(surface.worst_after <= surface.worst_before + 5.0);
  CHECK(surface.worst_translation_after < 0.02);
  bt::TrackerSettings features_only;
  features_only.recovery_surface_candidates = 0;
  CHECK(run(features_only).first_recovered == -1);  // features alone never come back
}

TEST_CASE("a textureless chair 2.5 m away comes back 27 degrees turned: re-acquired on return by its surface" * doctest::test_suite("end_to_end")) {
  synth::SyntheticSequenceSettings settings;  // the stress matrix's D_chair_2.5m_textureless_out_of_view
  settings.frames = 62;
  settings.shape = synth::Shape::Chair;
  settings.size = 0.70;
  settings.distance = 2.5;
  settings.textureless = true;
  settings.hidden_start = 40;  // back at frame 55, turned 27 degrees past the last frame seen
  settings.hidden_frames = 15;
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  const auto run = [&](const bt::TrackerSettings& tracking) {
    bt::DefaultTracker tracker(camera, tracking);
    struct {
      int lost_in_view = 0, wrong = 0;
    } out;
    for (int i = 0; i < settings.frames; ++i) {
      const synth::SyntheticFrame f = scene.frame(i);
      const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
      const bt::TrackResult r = i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame);
      const bool gone = i >= settings.hidden_start && i < settings.hidden_start + settings.hidden_frames;
      if (r.status == bt::TrackStatus::Lost) {
        out.lost_in_view += !gone;
        continue;
      }
      // Tracked poses of this cell stay within 3 degrees and 1 cm (bench/ACCURACY.md); a wrong
      // minimum (the chair turned by 90 degrees, seat and legs on the seen ones) is far off.
      out.wrong += bt::rotationErrorDeg(f.T_cam_obj, r.T_cam_obj) > 5.0 || bt::translationError(f.T_cam_obj, r.T_cam_obj) > 0.02;
    }
    MESSAGE("lost in view " << out.lost_in_view << ", wrong poses " << out.wrong);
    return out;
  };
  const auto turned = run(bt::TrackerSettings());
  CHECK(turned.lost_in_view == 0);
  CHECK(turned.wrong == 0);
  bt::TrackerSettings untuned;  // the candidates of before: the last good pose, moved onto the object
  untuned.recovery_turn_rings = 0;
  untuned.recovery_min_consensus = 1000;
  CHECK(run(untuned).lost_in_view >= 5);  // the right pose agrees with the keyframes at 0.57-0.68 only
}

/// The object leaves the view for 30 frames: reported lost while gone, recovered within 10 frames
/// of its return, and no wrong pose is ever reported as good.
template <typename Tracker>
void checkOutOfView(bool first_mask_only) {
  synth::SyntheticSequenceSettings settings;
  settings.frames = 100;
  settings.speed = 2.0;
  settings.hidden_start = 60;  // carried out of view near the turning point of the motion ...
  settings.hidden_frames = 30;  // ... and back at frame 90, 30 degrees from where it left
  const synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  Tracker tracker(camera);
  int lost_while_gone = 0, first_recovered = -1, wrong = 0;
  for (int i = 0; i < settings.frames; ++i) {
    const synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame =
        bt::makeFrame(std::to_string(i), f.color, f.depth, first_mask_only && i > 0 ? cv::Mat() : f.mask, camera);
    const bt::TrackResult r = i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame);
    const bool gone = i >= settings.hidden_start && i < settings.hidden_start + settings.hidden_frames;
    if (gone) lost_while_gone += r.status == bt::TrackStatus::Lost;
    if (r.status == bt::TrackStatus::Lost) continue;
    // Any pose the tracker stands behind must be right (5 deg, 1 cm), before and after the gap.
    wrong += bt::rotationErrorDeg(f.T_cam_obj, r.T_cam_obj) > 5.0 || bt::translationError(f.T_cam_obj, r.T_cam_obj) > 0.01;
    if (!gone && i >= settings.hidden_start && first_recovered < 0) first_recovered = i;
  }
  MESSAGE("lost while gone: " << lost_while_gone << " of 30, first good frame after return: " << first_recovered);
  CHECK(lost_while_gone == settings.hidden_frames);
  REQUIRE(first_recovered >= 0);
  CHECK(first_recovered - (settings.hidden_start + settings.hidden_frames) < 10);
  CHECK(wrong == 0);
}

TEST_CASE("object out of view for 30 frames with given masks: lost while gone and recovered on return with no wrong pose" * doctest::test_suite("end_to_end")) {
  checkOutOfView<bt::DefaultTracker>(false);
}

TEST_CASE("object out of view for 30 frames from the first mask only: lost while gone and found again on return" * doctest::test_suite("end_to_end")) {
  checkOutOfView<PropagatedTracker>(true);
}

/// Distance from p to the triangle abc: to the plane where p projects inside it, else to the
/// nearest edge.
double distanceToTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d q = p - n.dot(p - a) * n;  // p projected onto the plane
  const auto inside = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) { return (v - u).cross(q - u).dot(n) >= 0.0; };
  if (inside(a, b) && inside(b, c) && inside(c, a)) return std::abs(n.dot(p - a));
  const auto to_segment = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    return (p - (u + t * (v - u))).norm();
  };
  return std::min({to_segment(a, b), to_segment(b, c), to_segment(c, a)});
}

TEST_CASE("the object model fused from the keyframes lies on the true surface within the sensor's noise" * doctest::test_suite("end_to_end")) {
  const ShortScene short_scene(90);
  bt::DefaultTracker tracker(short_scene.camera());
  const Run run = track(tracker, short_scene.scene, short_scene.model);
  REQUIRE(run.lost == 0);
  const synth::TriangleMesh& mesh = short_scene.scene.objectMesh();
  const auto distance = [&](const Eigen::Vector3f& point) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles)
      nearest = std::min(nearest, distanceToTriangle(point.cast<double>(), mesh.positions[std::size_t(t[0])],
                                                     mesh.positions[std::size_t(t[1])], mesh.positions[std::size_t(t[2])]));
    return nearest;
  };
  const std::vector<bt::ModelPoint> model = bt::fuseObjectModel(tracker.keyframes());
  std::vector<double> errors;
  for (const bt::ModelPoint& p : model) errors.push_back(distance(p.position));
  std::sort(errors.begin(), errors.end());
  const double mean = std::accumulate(errors.begin(), errors.end(), 0.0) / double(errors.size());
  const double p95 = errors[errors.size() * 95 / 100];
  // Coverage: the true surface's samples within 1 cm of the model (the bottom is never seen).
  int covered = 0;
  for (const Eigen::Vector3f& truth : short_scene.model) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const bt::ModelPoint& p : model) nearest = std::min(nearest, double((p.position - truth).norm()));
    covered += nearest < 0.01;
  }
  const std::size_t unfiltered = bt::fuseObjectModel(tracker.keyframes(), {0.0f, 1}).size();
  MESSAGE(model.size() << " model points from " << tracker.keyframes().size() << " keyframes (" << unfiltered
                       << " without the outlier test); distance to the true surface: mean " << 1000 * mean
                       << " mm, 95th percentile " << 1000 * p95 << " mm, worst " << 1000 * errors.back()
                       << " mm; true surface covered within 1 cm: " << 100.0 * covered / double(short_scene.model.size()) << " %");
  // One reading of Kinect-class depth at the box's 0.73 m spreads by sigma = 1.4 mm
  // (DepthNoise::structuredLight); averaged over keyframes the model is closer than that.
  const double sigma = bt::DepthNoise::structuredLight().spread(0.73, 600.0);
  CHECK(mean < sigma);
  CHECK(p95 < 3.0 * sigma);
  CHECK(unfiltered > model.size());
  CHECK(covered > short_scene.model.size() / 3);
  // Colour: the box's printed texture is seen, not the flat grey of a missing image.
  int coloured = 0;
  for (const bt::ModelPoint& p : model) coloured += p.color != cv::Vec3b(0, 0, 0);
  CHECK(coloured > int(model.size()) * 9 / 10);
}

// Run-time composition: makeTracker against the trackers composed at compile time.

TEST_CASE("makeTracker builds the tracker composed at compile time: the same poses, given or propagated masks") {
  const ShortScene short_scene(6);
  const auto& [scene, model] = std::tie(short_scene.scene, short_scene.model);
  const Run composed = track(bt::DefaultTracker(short_scene.camera()), scene, model);
  CHECK(largestDifference(track(*bt::makeTracker(bt::Config(), short_scene.camera()), scene, model), composed) == 0.0);
  bt::Config config;
  config.masks = "propagated";
  const Run made = track(*bt::makeTracker(config, short_scene.camera()), scene, model, true);
  CHECK(largestDifference(made, track(PropagatedTracker(short_scene.camera()), scene, model, true)) == 0.0);
  // Serial and parallel execution give the same poses, bit for bit.
  config.execution = bt::Execution::Serial;
  CHECK(largestDifference(track(*bt::makeTracker(config, short_scene.camera()), scene, model, true), made) == 0.0);
}

TEST_CASE("frames preprocessed only inside the tracker's region of interest give the same poses bit for bit" * doctest::test_suite("end_to_end")) {
  // Given masks: the mask's box; propagated: around the last pose's silhouette; after the object
  // was out of view: the whole image until it is found again.
  synth::SyntheticSequenceSettings settings;
  settings.frames = 36;
  settings.hidden_start = 12;
  settings.hidden_frames = 8;
  const synth::SyntheticScene scene(settings);
  const auto model = scene.objectMesh().sampleSurface(1000, 1);
  const auto camera = settings.camera.cast<float>();
  const Run given = track(bt::DefaultTracker(camera), scene, model);
  CHECK(largestDifference(track(bt::DefaultTracker(camera), scene, model, false, {}, true), given) == 0.0);
  const Run propagated = track(PropagatedTracker(camera), scene, model, true);
  CHECK(propagated.lost >= 1);  // the whole-image case was exercised
  CHECK(largestDifference(track(PropagatedTracker(camera), scene, model, true, {}, true), propagated) == 0.0);
  // The region is smaller than the image once the track runs, and holds the object's mask.
  bt::DefaultTracker tracker(camera);
  const synth::SyntheticFrame first = scene.frame(0), next = scene.frame(1);
  CHECK(tracker.regionOfInterest(first.color.size(), first.mask) == cv::Rect({0, 0}, first.color.size()));
  tracker.initialize(bt::makeFrame("0", first.color, first.depth, first.mask, camera), first.T_cam_obj);
  const cv::Rect region = tracker.regionOfInterest(next.color.size(), next.mask);
  CHECK(region.area() < first.color.size().area() / 2);
  CHECK((region & cv::boundingRect(next.mask)) == cv::boundingRect(next.mask));
}

TEST_CASE("makeTracker applies the settings it is given and the coarse tracker it names") {
  const ShortScene short_scene(6);
  const auto& [scene, model] = std::tie(short_scene.scene, short_scene.model);
  bt::Config config;
  config.tracker = "coarse";
  const auto made = bt::makeTracker(config, short_scene.camera());
  CHECK(made->keyframeCount() == 0);
  CHECK(largestDifference(track(*made, scene, model), track(bt::DefaultCoarseTracker(), scene, model)) == 0.0);
  // A setting that matters moves the poses: Huber deltas a hundred times smaller.
  bt::Config tight;
  tight.dense_loss.delta = tight.feature_loss.delta = 5e-5;
  const Run composed = track(bt::DefaultTracker(short_scene.camera()), scene, model);
  CHECK(largestDifference(track(*bt::makeTracker(tight, short_scene.camera()), scene, model), composed) > 1e-6);
}

TEST_CASE("a first frame without depth under its mask or with a pose its depth contradicts is refused, naming the likely depth unit or the pose's mistake") {
  const ShortScene short_scene(1);
  const synth::SyntheticFrame f = short_scene.scene.frame(0);
  const auto initialize = [&](double depth_factor, const bt::SE3d& T_cam_obj) {
    const bt::RgbdFrame frame = bt::makeFrame("000000", f.color, f.depth * depth_factor, f.mask, short_scene.camera());
    bt::DefaultTracker(short_scene.camera()).initialize(frame, T_cam_obj);
    bt::DefaultCoarseTracker().initialize(frame, T_cam_obj);
  };
  const auto message = [&](double depth_factor, const bt::SE3d& T_cam_obj) -> std::string {
    try {
      initialize(depth_factor, T_cam_obj);
    } catch (const bt::InputError& error) {
      return error.what();
    }
    return "accepted";
  };
  CHECK_NOTHROW(initialize(1.0, f.T_cam_obj));  // the box's centre 0.73 m away, its near face ~0.1 m nearer
  CHECK_NOTHROW(initialize(5.0, bt::SE3d()));  // no pose known: nothing to compare
  // Depth in 0.2 mm units read as millimetres (x5), 0.1 mm (x10), and the inverse mistakes.
  CHECK(message(5.0, f.T_cam_obj).find("000000: the start pose puts the object's origin at depth 0.7") != std::string::npos);
  CHECK(message(5.0, f.T_cam_obj).find("the depth reads 5 times too far: depth.scale is probably 5 times too large") != std::string::npos);
  CHECK(message(10.0, f.T_cam_obj).find("10 times too far") != std::string::npos);
  CHECK(message(0.2, f.T_cam_obj).find("5 times too near: depth.scale is probably 5 times too small") != std::string::npos);
  CHECK(message(3.0, f.T_cam_obj).find("the depth scale is probably wrong") != std::string::npos);
  // Depth in 0.01 mm units read as 0.1 mm: the box 7 cm away, nearer than depth.min_depth.
  CHECK(message(0.1, f.T_cam_obj).find("no depth reading under the object's mask") != std::string::npos);
  CHECK(message(0.1, bt::SE3d()).find("no depth reading under the object's mask") != std::string::npos);
  // An origin behind the camera, and one beside the object: 0.3 m sideways the box's origin lies
  // 18.6 degrees beside its mask, which spans 13.1 degrees; 5 cm sideways it still passes.
  const bt::SE3d behind(f.T_cam_obj.rotation(), -f.T_cam_obj.translation());
  CHECK(message(1.0, behind).find("behind the camera (T_cam_obj maps object points into the camera frame") != std::string::npos);
  const auto beside = [&](double metres) {
    return bt::SE3d(f.T_cam_obj.rotation(), f.T_cam_obj.translation() + Eigen::Vector3d(metres, 0.0, 0.0));
  };
  CHECK(message(1.0, beside(0.3)).find("degrees beside the object's mask, which spans") != std::string::npos);
  CHECK(message(1.0, beside(0.05)) == "accepted");
  // A mask of one pixel: an origin within kStartMinSpanDeg of its ray passes, one farther does not.
  cv::Mat one_pixel = cv::Mat::zeros(f.mask.size(), CV_8UC1);
  int u = 0, v = 0;
  REQUIRE(short_scene.camera().pixelOf(f.T_cam_obj.translation().cast<float>(), u, v));
  one_pixel.at<uchar>(v, u) = 255;
  const auto with_one_pixel = [&](const bt::SE3d& T_cam_obj) {
    const bt::RgbdFrame frame = bt::makeFrame("000000", f.color, f.depth, one_pixel, short_scene.camera());
    bt::checkStartFrame(frame, T_cam_obj);
  };
  CHECK_NOTHROW(with_one_pixel(beside(0.005)));  // 0.4 degrees at 0.73 m
  CHECK_THROWS_AS(with_one_pixel(beside(0.05)), bt::InputError);  // 3.9 degrees
}

TEST_CASE("makeTracker refuses combinations that do not exist, naming the keys") {
  const bt::PinholeCameraf camera{600.0f, 600.0f, 319.5f, 239.5f};
  const auto problem = [&](const bt::Config& config) -> std::string {
    try {
      bt::makeTracker(config, camera);
    } catch (const std::invalid_argument& error) {
      return error.what();
    } catch (const std::runtime_error& error) {
      return std::string("runtime: ") + error.what();
    }
    return "";
  };
  bt::Config coarse_propagated;
  coarse_propagated.tracker = "coarse";
  coarse_propagated.masks = "propagated";
  CHECK(problem(coarse_propagated).find("tracker.type = coarse with masks.source = propagated") != std::string::npos);
  bt::Config coarse_gpu;
  coarse_gpu.tracker = "coarse";
  coarse_gpu.device = "gpu";
  CHECK(problem(coarse_gpu).find("compute.device = gpu") != std::string::npos);
  bt::Config unknown;
  unknown.features = "surf";
  CHECK(problem(unknown) == "features.type = 'surf': expected sift | orb | akaze");
  bt::Config gpu;
  gpu.device = "gpu";
  const std::string no_gpu = problem(gpu);
  // On a machine with a device and the backend, the GPU tracker is built.
  if (!no_gpu.empty()) CHECK(no_gpu.rfind("runtime: compute.device is gpu, but ", 0) == 0);
}

// A new residual term, written outside the library (feature_point_to_plane.hpp), is one header
// and one Term in an energy.

static_assert(bt::Residual<bt::testing::FeaturePointToPlane>);

TEST_CASE("a test-only feature point-to-plane term: its normal equations are the finite-difference gradient") {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const bt::SE3d T_i(bt::SO3d::exp(Eigen::Vector3d(0.3, -0.2, 0.1)), Eigen::Vector3d(0.02, -0.01, 0.7));
  const bt::SE3d T_j(bt::SO3d::exp(Eigen::Vector3d(0.25, -0.1, 0.3)), Eigen::Vector3d(0.05, 0.01, 0.65));
  bt::Keyframe ki, kj;
  std::vector<bt::FeatureMatch> matches;
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector3d p_obj(0.05 * normal(rng), 0.05 * normal(rng), 0.05 * normal(rng));
    const Eigen::Vector3d n_obj = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    ki.features.points.push_back((T_i * p_obj).cast<float>());
    ki.features.normals.push_back((T_i.rotation() * n_obj).cast<float>());
    kj.features.points.push_back((T_j * p_obj).cast<float>());
    kj.features.normals.push_back((T_j.rotation() * n_obj).cast<float>());
    matches.push_back({k, k});
  }
  using Plugin = bt::testing::FeaturePointToPlane;
  const auto system = [&](const bt::SE3d& A, const bt::SE3d& B) {
    bt::PairSystem s;
    Plugin{}.linearise(Plugin::input(bt::EdgeView{ki, kj, matches}), A, B, bt::TrivialLoss{}, 1.0, s);
    return s;
  };
  // Off the true poses, so that the residuals are not zero.
  const bt::SE3d A = T_i * bt::SE3d::exp((bt::SE3d::Tangent() << 0.003, -0.002, 0.001, 0.02, 0.01, -0.015).finished());
  const bt::SE3d B = T_j * bt::SE3d::exp((bt::SE3d::Tangent() << -0.001, 0.002, 0.003, -0.01, 0.02, 0.01).finished());
  const bt::PairSystem at = system(A, B);
  REQUIRE(at.residuals == 40);
  const Eigen::Matrix<double, 12, 1> gradient =
      halfCostGradient([&](const bt::SE3d& T_a, const bt::SE3d& T_b) { return system(T_a, T_b).cost; }, A, B, 1e-7);
  CAPTURE(gradient.transpose());
  CAPTURE(at.b.transpose());
  CHECK((gradient - at.b).norm() <= 1e-6 * at.b.norm());
}

TEST_CASE("a tracker with the test-only term in its energy tracks the synthetic box") {
  const ShortScene short_scene(12);
  const auto& [scene, model] = std::tie(short_scene.scene, short_scene.model);
  using WithPlugin = bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>,
                                bt::Term<bt::testing::FeaturePointToPlane, bt::HuberLoss>,
                                bt::Term<bt::DensePointToPlane, bt::HuberLoss>>;
  const Run with_term = track(
      bt::Tracker<WithPlugin, bt::PCG, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, bt::SurfaceAgreement>(short_scene.camera()),
      scene, model);
  const Run without = track(bt::DefaultTracker(short_scene.camera()), scene, model);
  MESSAGE("with the point-to-plane feature term: ADD-S " << with_term.score.adds_auc
                                                         << ", largest pose difference to the default "
                                                         << largestDifference(with_term, without));
  CHECK(with_term.lost == 0);
  CHECK(with_term.score.adds_auc >= 95.0);
  CHECK(largestDifference(with_term, without) > 1e-6);  // the term takes part in the optimisation
}

namespace {

/// A test-only term that pulls every node 10 cm along the camera's x axis from every earlier one,
/// strongly enough to override the data: a graph that runs away from its coarse pose.
struct RunAway {
  struct Input {};
  static Input input(const bt::EdgeView&) { return {}; }

  template <bt::RobustLoss Loss>
  void linearise(const Input&, const bt::SE3d& T_i, const bt::SE3d& T_j, const Loss& loss, double weight,
                 bt::PairSystem& system) const {
    // r = t_j - t_i - (0.1, 0, 0); under right perturbations a translation moves by R dv.
    const Eigen::Vector3d r = T_j.translation() - T_i.translation() - Eigen::Vector3d(0.1, 0.0, 0.0);
    Eigen::Matrix<double, 3, 6> J_i = Eigen::Matrix<double, 3, 6>::Zero(), J_j = Eigen::Matrix<double, 3, 6>::Zero();
    J_i.leftCols<3>() = -T_i.rotationMatrix();
    J_j.leftCols<3>() = T_j.rotationMatrix();
    system.add<3>(r, J_i, J_j, loss, weight);
  }
};

/// A verifier that trusts every graph, so that only the coarse-evidence check can refuse one.
struct TrustsEveryGraph {
  bool accepts(const bt::PoseGraph&, bt::Evidence) const { return true; }
};

}  // namespace

TEST_CASE("a graph result that throws away its coarse pose's RANSAC inliers is refused, the coarse pose stands") {
  const ShortScene short_scene(12);
  const auto& [scene, model] = std::tie(short_scene.scene, short_scene.model);
  using RunningAway = bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>, bt::Term<bt::DensePointToPlane, bt::HuberLoss>,
                                 bt::Term<RunAway, bt::TrivialLoss>>;
  using Pulled = bt::Tracker<RunningAway, bt::PCG, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, TrustsEveryGraph>;
  RunningAway energy;
  std::get<2>(energy.terms).weight = 1e6;
  bt::TrackerSettings settings;
  settings.keypoints = bt::KeypointSchedule::EveryFrame;  // every frame's coarse pose from RANSAC with the last frame
  const Run checked = track(Pulled(short_scene.camera(), settings, energy), scene, model);
  settings.min_kept_coarse_inliers = 0.0;
  const Run unchecked = track(Pulled(short_scene.camera(), settings, energy), scene, model);
  MESSAGE("graph pulled 10 cm away: ADD-S " << checked.score.adds_auc << ", mean translation error "
                                            << checked.score.translation_error_cm << " cm with the check (" << checked.tracked
                                            << " frames tracked), " << unchecked.score.adds_auc << ", "
                                            << unchecked.score.translation_error_cm << " cm without (" << unchecked.tracked << ")");
  // Without the check every runaway result is taken (frame 0 counts as tracked: initialize); with
  // it none is, and RANSAC's poses stand, within a few millimetres on this box.
  CHECK(unchecked.tracked == 12);
  CHECK(unchecked.score.translation_error_cm > 5.0);
  CHECK(checked.tracked == 1);
  CHECK(checked.lost == 0);
  CHECK(checked.score.translation_error_cm < 1.0);
  CHECK(checked.score.adds_auc > 90.0);
}

namespace {

/// SIFT whose matching without a known relative pose finds nothing, as when the last frame's
/// keypoints were followed from a frame whose view has turned away (their descriptors are that
/// frame's); matching gated by poses (the graph's edges) is untouched.
struct StaleDescriptors : bt::SiftFeatures {
  std::vector<bt::FeatureMatch> match(const bt::FrameFeatures& first, const bt::FrameFeatures& second,
                                      const std::optional<bt::MatchGate>& gate = std::nullopt) const {
    return gate ? bt::SiftFeatures::match(first, second, gate) : std::vector<bt::FeatureMatch>{};
  }
};

/// A verifier that trusts no graph: a frame stands only on its coarse pose.
struct RefusesEveryGraph {
  bool accepts(const bt::PoseGraph&, bt::Evidence) const { return false; }
};

}  // namespace

TEST_CASE("a frame whose followed keypoints' graph is refused keeps following's pose, not lost, when its detected ones match nothing") {
  const ShortScene short_scene(12);
  using Stale = bt::Tracker<bt::DefaultEnergy, bt::PCG, StaleDescriptors, bt::GivenMasks, bt::Ransac, RefusesEveryGraph>;
  const Run run = track(Stale(short_scene.camera()), short_scene.scene, short_scene.model);
  MESSAGE("every graph refused, no match without a pose: " << run.lost << " of 11 frames lost, " << run.followed
                                                           << " on followed keypoints, ADD-S " << run.score.adds_auc
                                                           << ", mean translation error " << run.score.translation_error_cm << " cm");
  // Every frame after the first: following's RANSAC pose (the frame's detected keypoints match
  // nothing, the graph is refused) stands as the coarse pose, and the next frame follows the
  // keypoints detected on it. Before, each such frame was reported lost at the first pose.
  CHECK(run.lost == 0);
  CHECK(run.tracked == 1);  // frame 0 (initialize); the others are CoarseOnly
  CHECK(run.followed == 11);
  // RANSAC over ~200 followed keypoints on a textured box 0.7 m away: within a few millimetres.
  CHECK(run.score.translation_error_cm < 0.5);
  CHECK(run.score.rotation_error_deg < 1.0);
}

namespace {

/// A verifier that trusts a graph only with one kind of evidence behind it (SurfaceOnly: no graph
/// reached from RANSAC's pose is taken).
template <bt::Evidence kTrusted>
struct TrustsOnly {
  bool accepts(const bt::PoseGraph&, bt::Evidence evidence) const { return evidence == kTrusted; }
};
using TrustsSurfaceOnly = TrustsOnly<bt::Evidence::SurfaceOnly>;

}  // namespace

TEST_CASE("a RANSAC pose on fewer inliers than chance gathers, its graph refused, gives way to the graph from the last pose") {
  const ShortScene short_scene(12);
  using Tracker = bt::Tracker<bt::DefaultEnergy, bt::PCG, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, TrustsSurfaceOnly>;
  bt::TrackerSettings settings;
  settings.keypoints = bt::KeypointSchedule::EveryFrame;  // every frame's coarse pose from RANSAC with the last frame
  const Run many = track(Tracker(short_scene.camera(), settings), short_scene.scene, short_scene.model);
  // The same frames, RANSAC's ~200 inliers on this textured box now below the count that counts
  // as more than chance: each refused graph is followed by the graph from the last good pose.
  settings.recovery_min_inliers = 100000;
  const Run few = track(Tracker(short_scene.camera(), settings), short_scene.scene, short_scene.model);
  MESSAGE("RANSAC's graphs refused: " << many.tracked << " frames tracked, ADD-S " << many.score.adds_auc
                                      << " on RANSAC's poses; with the last pose's graph: " << few.tracked << " tracked, ADD-S "
                                      << few.score.adds_auc << ", mean translation error " << few.score.translation_error_cm << " cm");
  CHECK(many.tracked == 1);  // frame 0 (initialize); the others stand on RANSAC's pose (CoarseOnly)
  CHECK(many.lost == 0);
  CHECK(few.tracked == 12);
  CHECK(few.lost == 0);
  // The graph over the keyframes from the last pose, with the frame's keypoints on its edges: a
  // textured box 0.7 m away within a few millimetres.
  CHECK(few.score.translation_error_cm < 0.5);
  CHECK(few.score.rotation_error_deg < 1.0);
}

TEST_CASE("a frame whose keypoints find no pose with the last frame is verified as one with the surface alone behind it") {
  const ShortScene short_scene(12);
  bt::TrackerSettings settings;
  settings.keypoints = bt::KeypointSchedule::EveryFrame;  // no graph by the surface alone first, no following
  // The frames' keypoints match nothing without a pose, so RANSAC never finds one with the last
  // frame and every graph starts from the last good pose. Before, that graph was verified as if a
  // registration stood behind it: a verifier refusing poses with the surface alone took it, and the
  // stricter test a surface-only graph had just failed (the 2 m box behind a pillar, 38 degrees
  // off) was passed on the second try.
  using BySurface = bt::Tracker<bt::DefaultEnergy, bt::PCG, StaleDescriptors, bt::GivenMasks, bt::Ransac, TrustsSurfaceOnly>;
  using ByFeatures = bt::Tracker<bt::DefaultEnergy, bt::PCG, StaleDescriptors, bt::GivenMasks, bt::Ransac, TrustsOnly<bt::Evidence::Features>>;
  const Run surface = track(BySurface(short_scene.camera(), settings), short_scene.scene, short_scene.model);
  const Run features = track(ByFeatures(short_scene.camera(), settings), short_scene.scene, short_scene.model);
  MESSAGE("no RANSAC pose: surface-only test " << surface.tracked << " tracked, " << surface.lost << " lost, ADD-S "
                                               << surface.score.adds_auc << "; feature test " << features.tracked
                                               << " tracked, " << features.lost << " lost");
  CHECK(surface.tracked == 12);
  CHECK(surface.lost == 0);
  CHECK(features.tracked == 1);  // frame 0 (initialize)
  CHECK(features.lost == 11);
  // The graph from the last pose, the frame's keypoints on its edges gated by the poses: the
  // textured box 0.7 m away within a few millimetres.
  CHECK(surface.score.translation_error_cm < 0.5);
  CHECK(surface.score.rotation_error_deg < 1.0);
}

TEST_CASE("a frame whose every candidate is refused gets a re-acquisition's candidates at once, not a frame later") {
  const ShortScene short_scene(12);
  bt::TrackerSettings settings;
  settings.keypoints = bt::KeypointSchedule::EveryFrame;  // no graph by the surface alone first, no following
  // No registration (the keypoints match nothing without a pose) and a verifier that trusts only
  // a pose reached from several starts: the graph from the last good pose is refused on every
  // frame, and only the re-acquisition's candidates, decided together, can hold one. Before, each
  // such frame was lost and the next, recovering, tracked: lost and tracked in turn.
  using Tracker = bt::Tracker<bt::DefaultEnergy, bt::PCG, StaleDescriptors, bt::GivenMasks, bt::Ransac,
                              TrustsOnly<bt::Evidence::SurfaceConsensus>>;
  const Run run = track(Tracker(short_scene.camera(), settings), short_scene.scene, short_scene.model);
  MESSAGE("only a consensus trusted: " << run.tracked << " tracked, " << run.lost << " lost, ADD-S " << run.score.adds_auc
                                       << ", mean errors " << run.score.rotation_error_deg << " deg, "
                                       << run.score.translation_error_cm << " cm");
  CHECK(run.lost == 0);
  CHECK(run.tracked == 12);
  // The consensus pose, refined by the graph with the frame's keypoints gated by it: the textured
  // box 0.7 m away within a few millimetres, as from the last pose above.
  CHECK(run.score.translation_error_cm < 0.5);
  CHECK(run.score.rotation_error_deg < 1.0);
}
