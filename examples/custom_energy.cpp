// custom_energy [--frames N]
// Composes trackers at compile time from energy terms, losses and solvers, and runs each on the
// same synthetic sequence (rendered in memory) against its exact ground truth:
//   a feature-only tracker (paper eq. 2 alone, Cauchy loss, dense LDLT solve) and
//   the full energy (eq. 2 + eq. 3 with Huber losses, PCG), i.e. bundletrack::DefaultTracker.
#include <cstdio>
#include <string>

#include "command_line.hpp"

#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "bundletrack/default_tracker.hpp"
#include "bundletrack/solvers/dense_ldlt.hpp"

namespace bt = bundletrack;

// The energy is a type: swap a term, a loss or a weight and the compiler builds a new tracker.
using FeatureOnlyEnergy = bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::CauchyLoss>>;
using FeatureOnlyTracker =
    bt::Tracker<FeatureOnlyEnergy, bt::DenseLDLT, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, bt::SurfaceAgreement>;

using FeatureAndDenseEnergy =
    bt::Energy<bt::Term<bt::FeaturePointToPoint, bt::HuberLoss>, bt::Term<bt::DensePointToPlane, bt::HuberLoss>>;
using FeatureAndDenseTracker =
    bt::Tracker<FeatureAndDenseEnergy, bt::PCG, bt::SiftFeatures, bt::GivenMasks, bt::Ransac, bt::SurfaceAgreement>;

template <typename Tracker>
void run(const char* label, Tracker tracker, const bt::synth::SyntheticScene& scene) {
  std::vector<bt::SE3d> truth, estimate;
  const auto camera = scene.settings().camera.cast<float>();
  for (int i = 0; i < scene.settings().frames; ++i) {
    const bt::synth::SyntheticFrame f = scene.frame(i);
    const bt::RgbdFrame frame = bt::makeFrame(std::to_string(i), f.color, f.depth, f.mask, camera);
    estimate.push_back((i == 0 ? tracker.initialize(frame, f.T_cam_obj) : tracker.track(frame)).T_cam_obj);
    truth.push_back(f.T_cam_obj);
  }
  const bt::SequenceScore s = bt::scoreSequence(scene.objectMesh().sampleSurface(2000, 1), truth, estimate);
  std::printf("%-18s ADD AUC %6.2f  ADD-S AUC %6.2f  R_err %5.2f deg  final ADD %.2f cm\n", label, s.add_auc,
              s.adds_auc, s.rotation_error_deg, s.final_add_cm);
}

int main(int argc, char** argv) {
  bt::synth::SyntheticSequenceSettings settings;
  settings.frames = 60;
  bt::examples::CommandLine command_line("Tracks the synthetic hand-held box with two energies composed at compile time.",
                                         "custom_energy");
  command_line.add_option("--frames", settings.frames, "frames of the synthetic box")->capture_default_str()->check(bt::examples::wholeAtLeast(1));
  command_line.parseOrExit(argc, argv);
  settings.speed = 2.0;
  const bt::synth::SyntheticScene scene(settings);
  const auto camera = settings.camera.cast<float>();
  std::printf("synthetic hand-held box, %d frames\n", settings.frames);
  run("feature only", FeatureOnlyTracker(camera), scene);
  run("feature + dense", FeatureAndDenseTracker(camera), scene);
  return 0;
}
