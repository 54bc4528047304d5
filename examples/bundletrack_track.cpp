// bundletrack_track --sequence DIR --out DIR [options]
// Tracks the object of a YCBInEOAT-layout sequence from its first pose and its masks (every
// frame's, or with --propagate-masks the first one only); writes OUT/poses/<frame>.txt (4x4
// T_cam_obj) and OUT/track.csv, and prints the accuracy when the sequence has ground truth and a
// model, and the propagated masks' IoU when it has masks.
#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <system_error>
#include <variant>

#include <unistd.h>

#include <opencv2/videoio.hpp>

#include "bundletrack/config/config_file.hpp"
#include "bundletrack/eval/mask_iou.hpp"
#include "bundletrack/eval/pose_metrics.hpp"
#include "bundletrack/eval/score_table.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/io/model_file.hpp"
#include "bundletrack/io/read_ahead.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/tracking/stopwatch.hpp"
#include "bundletrack/viz/overlay.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

const char* const kUsage = R"(usage: bundletrack_track --sequence DIR --out DIR [options]
  --config FILE      YAML settings over the defaults (see --print-config); options below override it
  --print-config     print the effective configuration as YAML and exit
  --print-config-table  print every setting with its default as a Markdown table and exit
  --features F       sift | orb | akaze (sift)
  --tracker T        full: pose graph over keyframes (paper IV) | coarse: frame-to-frame RANSAC only (full)
  --depth-scale S    metres per unit of the depth images (the layout's: 0.001 YCBInEOAT, 1/5000 TUM)
  --min-inliers N    fewest RANSAC inliers that count as a pose; fewer: the frame is lost (5)
  --inlier-mm D      RANSAC inlier distance in millimetres (5; widened by the sensor's noise)
  --sensor S         structured_light (Kinect v1, Xtion) | active_stereo (RealSense D4xx) |
                     time_of_flight (Azure Kinect): the depth noise every depth tolerance widens
                     with (sensor.model; structured_light)
  --gpu              matching, dense term, PCG and RANSAC on a CUDA device (compute.device: gpu;
                     needs a build with the CUDA backend and a GPU; keypoints stay on the CPU)
  --propagate-masks  the tracker gets only the first frame's mask and follows the object from it
                     (masks.source: propagated); later masks, where the sequence has them, are
                     read only to report each propagated mask's IoU in track.csv and a summary;
                     the masks used go to OUT/masks/<frame>.png
  --viz              write OUT/overlay.mp4 (pose axes, object box, mask outline per frame; an image
                     strip OUT/overlay_strip.png always, and in place of the video where no encoder
                     is available) and, with ground truth, OUT/errors.png (errors over time)
  --strict           a later frame that cannot be read (file missing or undecodable, depth without
                     a reading, no mask with given masks, no annotated pose) stops the run; by
                     default it is reported lost with the reason (track.csv: problem) and the run
                     goes on, the frame scored as a failure (without an annotated pose: not scored)
  --quiet            no progress line
)";

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "error: " << message << "\n" << kUsage;
  std::exit(2);
}

/// Sets the choice setting `key` to `name` as a command-line option asks; an unknown name fails.
void setChoice(bt::Config& config, const std::string& key, const std::string& option, const std::string& name) {
  for (const bt::ConfigEntry& entry : bt::configEntries(config)) {
    if (entry.name() != key) continue;
    const auto& choice = std::get<bt::ConfigChoice>(entry.value);
    if (std::find(choice.names.begin(), choice.names.end(), name) == choice.names.end())
      fail(option + " '" + name + "': expected " + choice.alternatives());
    choice.set(name);
  }
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
  bt::Config config;
  bool quiet = false;
  bool strict = false;  ///< --strict: a frame that cannot be read stops the run
  bool viz = false;
};

/// The overlays of --viz: a video when an encoder is available, and a strip of six frames.
class OverlayWriter {
 public:
  OverlayWriter(const fs::path& out, const bt::io::RgbdSequence& sequence)
      : out_(out), camera_(sequence.camera()), frames_(sequence.size()) {
    if (sequence.hasModel()) box_ = bt::ObjectBox::bounding(sequence.modelPoints());
    video_.open((out / "overlay.mp4").string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 10.0, sequence.imageSize());
  }

  void add(std::size_t i, const bt::RgbdFrame& frame, const bt::TrackResult& result) {
    cv::Mat image = frame.color.clone();
    if (!frame.mask.empty()) bt::viz::drawMaskContour(image, frame.mask, {0, 255, 255});
    double axis = 0.05;
    if (box_) {
      bt::viz::drawBox(image, camera_, result.T_cam_obj, *box_, {0, 220, 0}, 2);
      axis = 0.6 * (box_->max - box_->min).maxCoeff();
    }
    bt::viz::drawAxes(image, camera_, result.T_cam_obj, axis);
    const bool lost = result.status == bt::TrackStatus::Lost;
    cv::putText(image, frame.name + "  " + std::string(bt::statusName(result.status)), {10, 25},
                cv::FONT_HERSHEY_SIMPLEX, 0.7, lost ? cv::Scalar(0, 0, 255) : cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
    if (video_.isOpened()) video_.write(image);
    if (i % std::max<std::size_t>(1, frames_ / 6) == 0 && strip_.size() < 6) {
      cv::Mat half;
      cv::resize(image, half, {}, 0.5, 0.5, cv::INTER_AREA);
      strip_.push_back(half);
    }
  }

  /// Writes the strip; returns what a user should open.
  std::string finish() {
    cv::Mat strip;
    cv::hconcat(strip_, strip);
    const fs::path strip_path = out_ / "overlay_strip.png";
    if (!cv::imwrite(strip_path.string(), strip)) throw bt::InputError(strip_path, "cannot write image");
    return video_.isOpened() ? (out_ / "overlay.mp4").string() + " (and " + strip_path.string() + ")"
                             : strip_path.string() + " (no video encoder available)";
  }

 private:
  fs::path out_;
  bt::PinholeCamerad camera_;
  std::size_t frames_;
  std::optional<bt::ObjectBox> box_;
  cv::VideoWriter video_;
  std::vector<cv::Mat> strip_;
};

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
  return values[values.size() / 2];
}

/// A CSV field: quoted, with inner quotes doubled, when it holds a comma, a quote or a line break.
std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

/// Makes OUT/poses (and OUT/masks) and checks that files can be written there, before any work:
/// --out naming a file, a place without permission, a link loop or a name too long is said so.
void prepareOutput(const fs::path& out, bool masks) {
  std::error_code error;
  const fs::file_status status = fs::status(out, error);
  if (error && status.type() != fs::file_type::not_found)
    throw bt::InputError(out, "--out cannot be used: " + error.message());
  if (fs::exists(status) && !fs::is_directory(status))
    throw bt::InputError(out, "--out names a file, not a directory (the poses, track.csv and plots go into it)");
  for (const char* folder : {"poses", masks ? "masks" : nullptr}) {
    if (!folder) continue;
    fs::create_directories(out / folder, error);
    if (error) throw bt::InputError(out / folder, "--out: cannot create the directory: " + error.message());
  }
  const fs::path probe = out / "poses" / ".write_test";
  if (!std::ofstream(probe)) throw bt::InputError(out, std::string("--out is not writable: ") + std::strerror(errno));
  fs::remove(probe, error);
}

int run(bt::AnyTracker& tracker, const bt::io::RgbdSequence& sequence, const Options& options) {
  std::ofstream csv(options.out / "track.csv");
  const bool scored = sequence.hasGroundTruth() && sequence.hasModel();
  // Read before the work: a model that cannot be read (empty, not numbers) stops the run now, not
  // after every frame was tracked.
  const std::vector<Eigen::Vector3f> model = scored ? sequence.modelPoints() : std::vector<Eigen::Vector3f>();
  const bool propagated = options.config.masks == "propagated";
  csv << "frame,status,by_surface,keypoints,matches,inliers,read_ms,mask_ms,features_ms,matching_ms,ransac_ms,graph_ms,solve_ms,total_ms"
      << (scored ? ",rotation_error_deg,translation_error_cm" : "") << (propagated ? ",mask_iou" : "") << ",problem\n";
  std::vector<bt::SE3d> truth;
  std::vector<std::optional<bt::SE3d>> estimate;  // none: the frame could not be read, a failure for the scores
  std::vector<std::optional<bt::SE3d>> estimate_unless_lost;  // none also where the tracker lost the object
  int lost = 0, unreadable = 0, unscored = 0, by_surface = 0;
  std::string first_unreadable;
  bt::SE3d last_pose;  // what a frame that cannot be read reports
  const bool interactive = isatty(fileno(stderr));
  std::optional<OverlayWriter> overlay;
  if (options.viz) overlay.emplace(options.out, sequence);
  std::vector<double> rotation_errors, translation_errors, mask_ious, total_ms, read_ms_all, features_ms;
  std::vector<bool> lost_scored;  // per scored frame, for the error plot
  // Files are decoded a few frames ahead on another thread; each frame is preprocessed only where
  // the tracker will look (Tracker::regionOfInterest).
  bt::io::ReadAhead<bt::RawFrame> files(sequence.size(), [&](std::size_t i) { return sequence.read(i); });
  bt::Stopwatch whole_run, progress;
  double elapsed_ms = 0.0, shown_ms = -1e9;  // since the start, and when the progress line was drawn
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    bt::Stopwatch reading;
    // A frame whose files cannot be read (or, with given masks, has no mask) is reported lost with
    // the reason and keeps the last pose; the run goes on. Not so for the first frame, nor with --strict.
    std::optional<bt::RgbdFrame> frame;
    cv::Mat dataset_mask;
    std::string problem;
    try {
      bt::RawFrame raw = files.next();
      dataset_mask = raw.mask;
      if (propagated && i > 0) raw.mask = cv::Mat();  // the tracker must not see it
      if (!propagated && i > 0 && raw.mask.empty())
        throw bt::InputError(sequence.maskPath(i), "file not found: tracking with given masks needs a mask for "
                                                   "every frame (or use --propagate-masks)");
      const cv::Rect region = tracker.regionOfInterest(raw.color.size(), raw.mask);
      frame = sequence.preprocess(std::move(raw), region);
    } catch (const bt::InputError& error) {
      if (i == 0 || options.strict) throw;
      problem = error.what();
    }
    const double read_ms = reading.lap();
    const std::string name = sequence.frameNames()[i];
    bt::TrackResult result;
    if (frame) {
      const bt::SE3d initial = sequence.hasGroundTruth() ? sequence.groundTruthPose(0) : bt::SE3d();
      result = i == 0 ? tracker.initialize(*frame, initial) : tracker.track(*frame);
    } else {
      result.T_cam_obj = last_pose;
      result.status = bt::TrackStatus::Lost;
      if (unreadable++ == 0) first_unreadable = problem;
      if (!options.quiet) std::fprintf(stderr, "%sframe %s lost: %s\n", interactive ? "\n" : "", name.c_str(), problem.c_str());
    }
    last_pose = result.T_cam_obj;
    if (i == 0) whole_run.lap();  // the whole run's time counts from the first tracked frame
    lost += result.status == bt::TrackStatus::Lost;
    by_surface += result.surface_only;
    bt::io::writePose(options.out / "poses" / (name + ".txt"), result.T_cam_obj);
    const auto& t = result.timings;
    if (i > 0 && frame) total_ms.push_back(t.total), read_ms_all.push_back(read_ms), features_ms.push_back(t.features);
    csv << name << ',' << bt::statusName(result.status) << ',' << result.surface_only << ',' << result.keypoints << ',' << result.matches << ','
        << result.inliers << ',' << read_ms << ',' << t.mask << ',' << t.features << ',' << t.matching << ',' << t.ransac << ',' << t.graph
        << ',' << t.solve << ',' << t.total;
    if (scored) {
      // A frame without an annotated pose is not scored; one that could not be read scores as a failure.
      std::optional<bt::SE3d> true_pose;
      try {
        true_pose = sequence.groundTruthPose(i);
      } catch (const bt::InputError& error) {
        if (i == 0 || options.strict) throw;
        ++unscored;
        if (problem.empty()) problem = std::string(error.what()) + " (frame not scored)";
      }
      csv << ',';
      if (true_pose) {
        truth.push_back(*true_pose);
        estimate.push_back(frame ? std::optional(result.T_cam_obj) : std::nullopt);
        estimate_unless_lost.push_back(result.status != bt::TrackStatus::Lost ? std::optional(result.T_cam_obj)
                                                                              : std::nullopt);
        rotation_errors.push_back(bt::rotationErrorDeg(*true_pose, result.T_cam_obj));
        translation_errors.push_back(100.0 * bt::translationError(*true_pose, result.T_cam_obj));
        lost_scored.push_back(result.status == bt::TrackStatus::Lost);
        csv << rotation_errors.back() << ',' << translation_errors.back();
      } else {
        csv << ',';
      }
    }
    if (propagated) {
      // A frame lost before a mask was made counts as an empty mask.
      const cv::Mat used = result.mask.empty() ? cv::Mat::zeros(sequence.imageSize(), CV_8UC1) : result.mask;
      const fs::path mask_path = options.out / "masks" / (name + ".png");
      if (!cv::imwrite(mask_path.string(), used)) throw bt::InputError(mask_path, "cannot write image");
      if (!dataset_mask.empty()) mask_ious.push_back(bt::maskIoU(used > 0, dataset_mask > 0));
      csv << ',';
      if (!dataset_mask.empty()) csv << mask_ious.back();
    }
    if (frame && overlay) {
      frame->mask = result.mask;  // the overlay outlines the mask the tracker used
      overlay->add(i, *frame, result);
    }
    csv << ',' << csvField(problem) << '\n';
    // Progress: on a terminal one line redrawn ten times a second, in a log a line every 50 frames;
    // the rate and the time left from the frames so far.
    elapsed_ms += progress.lap();
    const bool last = i + 1 == sequence.size();
    if (!options.quiet && (interactive ? elapsed_ms - shown_ms >= 100.0 || last : (i + 1) % 50 == 0 || last)) {
      shown_ms = elapsed_ms;
      const double per_frame_ms = elapsed_ms / double(i + 1);
      std::fprintf(stderr, "%sframe %zu/%zu  %-7s  inliers %3d/%-3d  %5.1f ms  |  %.1f fps, %d lost, %.0f s left%s",
                   interactive ? "\r" : "", i + 1, sequence.size(), std::string(bt::statusName(result.status)).c_str(),
                   result.inliers, result.matches, t.total, 1000.0 / per_frame_ms, lost,
                   per_frame_ms * double(sequence.size() - i - 1) / 1000.0, interactive ? "   " : "\n");
    }
  }
  const double run_ms = whole_run.lap();  // frames 1 .. n-1 with writing the results
  if (!options.quiet && interactive) std::fprintf(stderr, "\n");
  std::printf("%s: %zu frames, %d lost; poses in %s\n", options.sequence.string().c_str(), sequence.size(), lost,
              (options.out / "poses").string().c_str());
  if (unreadable > 0)
    std::printf("%d of the lost frames could not be read (first: %s); the reasons are in track.csv's problem column\n",
                unreadable, first_unreadable.c_str());
  if (unscored > 0) std::printf("%d frames without an annotated pose were not scored\n", unscored);
  if (by_surface > 0)
    std::printf("%d frames tracked by the dense term alone, without keypoints (features.detect: on_demand)\n", by_surface);
  // Rates only where something was tracked: the time of frames that were all lost is no frame rate.
  if (sequence.size() > 1 && lost == int(sequence.size()) - 1) {
    std::printf("no frame after the first was tracked: no frame rate\n");
  } else if (!total_ms.empty()) {
    const double tracking = median(total_ms);
    std::printf("median per frame: %.1f ms tracking (%.1f fps; keypoint detection %.1f ms of it), %.1f ms waiting "
                "for its files and preprocessing it; per stage in track.csv\n",
                tracking, 1000.0 / tracking, median(features_ms), median(read_ms_all));
    const double per_frame = run_ms / double(sequence.size() - 1);
    std::printf("whole run after the first frame: %.1f ms per frame from the files to the poses written (%.1f fps)\n",
                per_frame, 1000.0 / per_frame);
  }
  if (!mask_ious.empty()) {
    double sum = 0.0;
    for (const double iou : mask_ious) sum += iou;
    std::printf("propagated mask IoU against the sequence's masks: mean %.3f, min %.3f over %zu frames\n",
                sum / double(mask_ious.size()), *std::min_element(mask_ious.begin(), mask_ious.end()), mask_ious.size());
  }
  if (const std::vector<bt::ModelPoint> object = tracker.objectModel(); !object.empty()) {
    bt::io::writeModelPly(options.out / "model.ply", object);
    std::printf("object model: %s (%zu points fused from %zu keyframes)\n", (options.out / "model.ply").string().c_str(),
                object.size(), tracker.keyframeCount());
  }
  if (scored) {
    // A lost frame keeps the last good pose, which the first row scores as its estimate; where
    // frames were lost, a second row scores them as failures.
    const std::string name = options.sequence.filename().string();
    const bt::SequenceScore score = bt::scoreSequence(model, truth, estimate);
    std::vector<bt::NamedScore> rows = {{name, score}};
    if (lost > 0) rows.push_back({name + " (lost=failed)", bt::scoreSequence(model, truth, estimate_unless_lost)});
    std::printf("%s", bt::formatScoreTable(rows, bt::MeanRow::Omit).c_str());  // two views of one run: no mean
    std::printf("final-frame ADD %.2f cm\n", score.final_add_cm);
  }
  if (overlay) {
    std::printf("overlay: %s\n", overlay->finish().c_str());
    if (scored) {
      const fs::path plot = options.out / "errors.png";
      // A lost frame keeps the last pose, which the tracker does not stand behind: a gap, shaded.
      const auto unless_lost = [&](std::vector<double> errors) {
        for (std::size_t k = 0; k < errors.size(); ++k)
          if (lost_scored[k]) errors[k] = std::numeric_limits<double>::quiet_NaN();
        return errors;
      };
      const cv::Mat errors = bt::viz::plotErrors({{"rotation error [deg]", unless_lost(rotation_errors)},
                                                  {"translation error [cm]", unless_lost(translation_errors)}},
                                                 lost_scored);
      if (!cv::imwrite(plot.string(), errors)) throw bt::InputError(plot, "cannot write image");
      std::printf("error plot: %s\n", plot.string().c_str());
    }
  }
  return 0;
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
    else if (arg == "--tracker") overrides.emplace_back(arg, value());
    else if (arg == "--config") options.config_file = value();
    else if (arg == "--print-config") print_config = true;
    else if (arg == "--print-config-table") {
      std::cout << bt::settingsTable();
      return 0;
    }
    else if (arg == "--features" || arg == "--depth-scale" || arg == "--min-inliers" || arg == "--inlier-mm" ||
             arg == "--sensor")
      overrides.emplace_back(arg, value());
    else if (arg == "--propagate-masks" || arg == "--gpu") overrides.emplace_back(arg, "");
    else if (arg == "--quiet") options.quiet = true;
    else if (arg == "--strict") options.strict = true;
    else if (arg == "--viz") options.viz = true;
    else if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    } else fail("unknown option '" + arg + "'");
  }
  try {
    if (!options.config_file.empty()) options.config = bt::loadConfig(options.config_file);
    auto& config = options.config;
    for (const auto& [option, text] : overrides) {
      if (option == "--tracker") config.tracker = text;
      else if (option == "--features") config.features = text;
      else if (option == "--depth-scale") bt::setNumber(config, "depth.scale", number(option, text), option + " " + text);
      else if (option == "--min-inliers") bt::setNumber(config, "ransac.min_inliers", number(option, text), option + " " + text);
      else if (option == "--inlier-mm")
        bt::setNumber(config, "ransac.inlier_distance", number(option, text) * 1e-3, option + " " + text);
      else if (option == "--sensor") setChoice(config, "sensor.model", option, text);
      else if (option == "--propagate-masks") config.masks = "propagated";
      else if (option == "--gpu") config.device = "gpu";
    }
    bt::requireConsistent(config, options.config_file.empty() ? fs::path("the options") : options.config_file);
    if (print_config) {
      std::cout << bt::printConfig(config);
      return 0;
    }
    if (options.sequence.empty() || options.out.empty()) fail("--sequence and --out are required");
    prepareOutput(options.out, config.masks == "propagated");
    const bt::io::RgbdSequence sequence(options.sequence, config.sequence);
    const std::unique_ptr<bt::AnyTracker> tracker = bt::makeTracker(config, sequence.camera().cast<float>());
    return run(*tracker, sequence, options);
  } catch (const std::invalid_argument& error) {
    fail(error.what());
  } catch (const std::exception& error) {
    std::cerr << "\nerror: " << error.what() << '\n';
    return 1;
  }
}
