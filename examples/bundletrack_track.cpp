// bundletrack_track --sequence DIR --out DIR [options]
// Tracks the object of a YCBInEOAT-layout sequence from its first mask and pose; writes
// OUT/poses/<frame>.txt (4x4 T_cam_obj) and OUT/track.csv, and prints the accuracy when the
// sequence has ground truth and a model.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include <unistd.h>

#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/io/config.hpp"
#include "bundletrack/tracker.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

const char* const kUsage = R"(usage: bundletrack_track --sequence DIR --out DIR [options]
  --config FILE      YAML settings over the defaults (see --print-config); options below override it
  --print-config     print the effective configuration as YAML and exit
  --features F       sift | orb | akaze (sift)
  --tracker T        full: pose graph over keyframes (paper IV) | coarse: frame-to-frame RANSAC only (full)
  --depth-scale S    metres per unit of the depth images (0.001)
  --min-inliers N    fewest RANSAC inliers that count as a pose; fewer: the frame is lost (5)
  --inlier-mm D      RANSAC inlier distance in millimetres (5)
  --quiet            no progress line
)";

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "error: " << message << "\n" << kUsage;
  std::exit(2);
}

double number(const std::string& option, const std::string& text) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size() && std::isfinite(value)) return value;
  } catch (const std::exception&) {
  }
  fail(option + " expects a number, got '" + text + "'");
}

struct Options {
  fs::path sequence, out, config_file;
  std::string tracker = "full";
  bt::io::Config config;
  bool quiet = false;
};

template <typename Tracker>
int run(Tracker tracker, const bt::io::YcbineoatSequence& sequence, const Options& options) {
  fs::create_directories(options.out / "poses");
  std::ofstream csv(options.out / "track.csv");
  const bool scored = sequence.hasGroundTruth() && sequence.hasModel();
  csv << "frame,status,keypoints,matches,inliers,mask_ms,features_ms,matching_ms,ransac_ms,graph_ms,solve_ms,total_ms"
      << (scored ? ",rotation_error_deg,translation_error_cm\n" : "\n");
  std::vector<bt::SE3d> truth, estimate;
  int lost = 0;
  const bool interactive = isatty(fileno(stderr));
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const bt::RgbdFrame frame = sequence.frame(i);
    if (i > 0 && frame.mask.empty())
      throw bt::InputError(options.sequence / "masks" / (frame.name + ".png"),
                           "file not found: tracking with given masks needs a mask for every frame");
    const bt::SE3d initial = sequence.hasGroundTruth() ? sequence.groundTruthPose(0) : bt::SE3d();
    const bt::TrackResult result = i == 0 ? tracker.initialize(frame, initial) : tracker.track(frame);
    lost += result.status == bt::TrackStatus::Lost;
    bt::io::writePose(options.out / "poses" / (frame.name + ".txt"), result.T_cam_obj);
    const auto& t = result.timings;
    csv << frame.name << ',' << bt::statusName(result.status) << ',' << result.keypoints << ',' << result.matches << ','
        << result.inliers << ',' << t.mask << ',' << t.features << ',' << t.matching << ',' << t.ransac << ',' << t.graph
        << ',' << t.solve << ',' << t.total;
    if (scored) {
      truth.push_back(sequence.groundTruthPose(i));
      estimate.push_back(result.T_cam_obj);
      csv << ',' << bt::rotationErrorDeg(truth.back(), estimate.back()) << ','
          << 100.0 * bt::translationError(truth.back(), estimate.back());
    }
    csv << '\n';
    // On a terminal one line updated in place; in a log a line every 50 frames.
    if (!options.quiet && (interactive || (i + 1) % 50 == 0 || i + 1 == sequence.size()))
      std::fprintf(stderr, "%sframe %zu/%zu  %-7s  inliers %3d/%-3d  %.1f ms%s", interactive ? "\r" : "", i + 1,
                   sequence.size(), std::string(bt::statusName(result.status)).c_str(), result.inliers,
                   result.matches, t.total, interactive ? " " : "\n");
  }
  if (!options.quiet && interactive) std::fprintf(stderr, "\n");
  std::printf("%s: %zu frames, %d lost; poses in %s\n", options.sequence.string().c_str(), sequence.size(), lost,
              (options.out / "poses").string().c_str());
  if (scored) {
    const bt::SequenceScore s = bt::scoreSequence(sequence.modelPoints(), truth, estimate);
    std::printf("ADD AUC %.2f  ADD-S AUC %.2f  5deg5cm %.1f%%  R_err %.2f deg  T_err %.2f cm  final ADD %.2f cm\n",
                s.add_auc, s.adds_auc, s.deg5cm5, s.rotation_error_deg, s.translation_error_cm, s.final_add_cm);
  }
  return 0;
}

template <typename Source>
int runWith(const Options& options, const typename Source::Settings& source_settings) {
  const bt::io::YcbineoatSequence sequence(options.sequence, options.config.sequence);
  const bt::TrackerSettings& settings = options.config.tracker;
  if (options.tracker == "coarse") return run(bt::CoarseTracker<Source>(Source(source_settings), settings.coarse), sequence, options);
  using Tracker = bt::Tracker<bt::DefaultEnergy, bt::PCG, Source>;
  return run(Tracker(sequence.camera().cast<float>(), settings, {}, {}, Source(source_settings)), sequence, options);
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  bool print_config = false;
  std::vector<std::pair<std::string, std::string>> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) fail(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--sequence") options.sequence = value();
    else if (arg == "--out") options.out = value();
    else if (arg == "--tracker") options.tracker = value();
    else if (arg == "--config") options.config_file = value();
    else if (arg == "--print-config") print_config = true;
    else if (arg == "--features" || arg == "--depth-scale" || arg == "--min-inliers" || arg == "--inlier-mm")
      overrides.emplace_back(arg, value());
    else if (arg == "--quiet") options.quiet = true;
    else if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    } else fail("unknown option '" + arg + "'");
  }
  try {
    if (!options.config_file.empty()) options.config = bt::io::loadConfig(options.config_file);
    auto& config = options.config;
    for (const auto& [option, text] : overrides) {
      if (option == "--features") config.features = text;
      else if (option == "--depth-scale") config.sequence.depth_scale = number(option, text);
      else if (option == "--min-inliers") config.tracker.coarse.min_inliers = int(number(option, text));
      else if (option == "--inlier-mm") config.tracker.coarse.ransac.inlier_distance = float(number(option, text) * 1e-3);
    }
    if (print_config) {
      std::cout << bt::io::printConfig(config);
      return 0;
    }
    if (options.sequence.empty() || options.out.empty()) fail("--sequence and --out are required");
    if (options.tracker != "coarse" && options.tracker != "full") fail("unknown tracker '" + options.tracker + "'");
    if (config.features == "sift") return runWith<bt::SiftFeatures>(options, config.sift);
    if (config.features == "orb") return runWith<bt::OrbFeatures>(options, config.orb);
    if (config.features == "akaze") return runWith<bt::AkazeFeatures>(options, config.akaze);
    fail("unknown features '" + config.features + "'");
  } catch (const std::exception& error) {
    std::cerr << "\nerror: " << error.what() << '\n';
    return 1;
  }
}
