// bundletrack_track --sequence DIR --out DIR [options]
// Tracks the object of a sequence (YCBInEOAT or TUM RGB-D layout) from its first pose and its
// masks (every frame's, or with --propagate-masks the first one only); writes
// OUT/poses/<frame>.txt (4x4 T_cam_obj) and OUT/track.csv, and prints the accuracy when the
// sequence has ground truth and a model, and the propagated masks' IoU when it has masks. A
// sequence of several objects (a folder of masks per object) gets OUT/<object>/ for each.
#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <variant>

#include <unistd.h>

#include <opencv2/videoio.hpp>

#include "command_line.hpp"

#include "bundletrack/config/config_file.hpp"
#include "bundletrack/core/frame_memory.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/core/start_frame_check.hpp"
#include "bundletrack/eval/mask_iou.hpp"
#include "bundletrack/eval/pose_metrics.hpp"
#include "bundletrack/eval/score_table.hpp"
#include "bundletrack/eval/sequence_score.hpp"
#include "bundletrack/io/frame_ahead.hpp"
#include "bundletrack/io/model_file.hpp"
#include "bundletrack/io/read_ahead.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/tracking/multi_object_tracker.hpp"
#include "bundletrack/tracking/stopwatch.hpp"
#include "bundletrack/viz/overlay.hpp"

namespace bt = bundletrack;
namespace fs = std::filesystem;

namespace {

/// Sets the choice setting `key` to `name` as a command-line option asks; an unknown name fails.
void setChoice(const bt::examples::CommandLine& command_line, bt::Config& config, const std::string& key,
               const std::string& option, const std::string& name) {
  for (const bt::ConfigEntry& entry : bt::configEntries(config)) {
    if (entry.name() != key) continue;
    const auto& choice = std::get<bt::ConfigChoice>(entry.value);
    if (std::find(choice.names.begin(), choice.names.end(), name) == choice.names.end())
      command_line.fail(option + " '" + name + "': expected " + choice.alternatives());
    choice.set(name);
  }
}

double number(const bt::examples::CommandLine& command_line, const std::string& option, const std::string& text) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size() && std::isfinite(value)) return value;
  } catch (const std::exception&) {
  }
  command_line.fail(option + " expects a number, got '" + text + "'");
}

struct Options {
  fs::path sequence, out, config_file;
  std::string objects;  ///< --objects: names separated by commas, or "all"
  bt::Config config;
  bool quiet = false;
  bool no_score = false;  ///< --no-score: no ADD / ADD-S table at the end
  bool strict = false;  ///< --strict: a frame that cannot be read stops the run
  bool viz = false;
};

/// The objects --objects names ("" or "all": every one), checked against the sequence's; {""}
/// for a sequence of one object.
std::vector<std::string> chosenObjects(const bt::io::RgbdSequence& sequence, const std::string& list) {
  const std::vector<std::string>& available = sequence.objects();
  std::string names;
  for (const std::string& name : available) names += (names.empty() ? "" : ", ") + name;
  if (available.empty()) {
    if (!list.empty())
      throw std::invalid_argument("--objects " + list + ": " + (sequence.root() / "masks").string() +
           " holds the masks of one object (masks/<frame>.png), not a folder per object nor label images");
    return {""};
  }
  if (list.empty() || list == "all") return available;
  std::vector<std::string> chosen;
  std::stringstream items(list);
  for (std::string name; std::getline(items, name, ',');) {
    if (std::find(available.begin(), available.end(), name) == available.end())
      throw std::invalid_argument("--objects: no object '" + name + "' in " + sequence.objectList().string() + " (it has " + names + ")");
    if (std::find(chosen.begin(), chosen.end(), name) != chosen.end()) throw std::invalid_argument("--objects names '" + name + "' twice");
    chosen.push_back(name);
  }
  if (chosen.empty()) throw std::invalid_argument("--objects needs at least one name (it has " + names + ")");
  return chosen;
}

/// One object as the overlay draws it.
struct DrawnObject {
  std::string label;  ///< "" for a single object
  const bt::TrackResult* result;  ///< none: the object has not started
  const std::optional<bt::ObjectBox>* box;
};

/// The overlays of --viz: a video when an encoder is available, and a strip of six frames.
class OverlayWriter {
 public:
  OverlayWriter(const fs::path& out, const bt::io::RgbdSequence& sequence)
      : out_(out), camera_(sequence.camera()), frames_(sequence.size()) {
    video_.open((out / "overlay.mp4").string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 10.0, sequence.imageSize());
  }

  /// Frame i with each object's mask outline, box and axes (an object's own colour when several).
  void add(std::size_t i, const bt::RgbdFrame& frame, const std::vector<DrawnObject>& objects) {
    static const cv::Scalar kColours[] = {{0, 220, 0}, {255, 160, 0}, {200, 0, 255}, {0, 200, 255}};
    cv::Mat image = frame.color.clone();
    std::string caption = frame.name;
    bool any_lost = false;
    for (std::size_t k = 0; k < objects.size(); ++k) {
      const DrawnObject& object = objects[k];
      const std::string status = object.result ? std::string(bt::statusName(object.result->status)) : "not started";
      caption += "  " + (object.label.empty() ? status : object.label + " " + status);
      if (!object.result) continue;
      const bt::TrackResult& result = *object.result;
      any_lost = any_lost || result.status == bt::TrackStatus::Lost;
      const cv::Scalar colour = objects.size() == 1 ? kColours[0] : kColours[k % std::size(kColours)];
      if (!result.mask.empty()) bt::viz::drawMaskContour(image, result.mask, objects.size() == 1 ? cv::Scalar(0, 255, 255) : colour);
      double axis = 0.05;
      if (*object.box) {
        bt::viz::drawBox(image, camera_, result.T_cam_obj, **object.box, colour, 2);
        axis = 0.6 * ((*object.box)->max - (*object.box)->min).maxCoeff();
      }
      bt::viz::drawAxes(image, camera_, result.T_cam_obj, axis);
    }
    cv::putText(image, caption, {10, 25}, cv::FONT_HERSHEY_SIMPLEX, 0.7, any_lost ? cv::Scalar(0, 0, 255) : cv::Scalar(255, 255, 255),
                2, cv::LINE_AA);
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

/// Whether every object to track has a mask for one frame only: the input the method starts from
/// ("a mask of the object in the first frame"), past which given masks cannot track. A sequence of
/// label images counts its label images (one holds every object's mask of that frame).
bool oneMaskEach(const bt::io::RgbdSequence& sequence, const std::vector<std::string>& objects) {
  if (sequence.size() < 2) return false;
  for (const std::string& object : objects) {
    int masks = 0;
    for (std::size_t i = 0; i < sequence.size() && masks < 2; ++i) masks += fs::exists(sequence.maskPath(i, object));
    if (masks != 1) return false;
  }
  return true;
}

/// Makes `out` with its `folders` and checks that files can be written there, before any work:
/// --out naming a file, a place without permission, a link loop or a name too long is said so.
void prepareOutput(const fs::path& out, std::vector<fs::path> folders) {
  folders.insert(folders.begin(), ".");
  std::error_code error;
  const fs::file_status status = fs::status(out, error);
  if (error && status.type() != fs::file_type::not_found)
    throw bt::InputError(out, "--out cannot be used: " + error.message());
  if (fs::exists(status) && !fs::is_directory(status))
    throw bt::InputError(out, "--out names a file, not a directory (the poses, track.csv and plots go into it)");
  for (const fs::path& folder : folders) {
    const fs::path directory = folder == "." ? out : out / folder;
    fs::create_directories(directory, error);
    if (error) throw bt::InputError(directory, "--out: cannot create the directory: " + error.message());
  }
  const fs::path probe = out / ".write_test";
  if (!std::ofstream(probe)) throw bt::InputError(out, std::string("--out is not writable: ") + std::strerror(errno));
  fs::remove(probe, error);
}

/// What a run writes and reports of one object: in OUT itself for the only object of a sequence,
/// in OUT/<object> for each of several -- poses/<frame>.txt, track.csv, masks/ (propagated masks),
/// model.ply, errors.png -- and its tallies for the summary.
class ObjectOutput {
 public:
  ObjectOutput(std::string object, fs::path out, const bt::io::RgbdSequence& sequence, const Options& options)
      : object_(std::move(object)), out_(std::move(out)), sequence_(sequence),
        propagated_(options.config.masks == "propagated"), strict_(options.strict),
        scored_(sequence.hasGroundTruth(object_) && sequence.hasModel(object_)) {
    // Read before the work: a model that cannot be read (empty, not numbers) stops the run now, not
    // after every frame was tracked.
    if (scored_ || (options.viz && sequence.hasModel(object_))) {
      model_ = sequence.modelPoints(object_);
      box_ = bt::ObjectBox::bounding(model_);
    }
    csv_.open(out_ / "track.csv");
    csv_ << "frame,status,by_surface,keypoints,followed,matches,inliers,stability,read_ms,mask_ms,features_ms,matching_ms,ransac_ms,graph_ms,solve_ms,"
            "total_ms"
         << (scored_ ? ",rotation_error_deg,translation_error_cm" : "") << (propagated_ ? ",mask_iou" : "") << ",problem\n";
  }

  const std::string& object() const { return object_; }
  const std::optional<bt::ObjectBox>& box() const { return box_; }
  int lost() const { return lost_; }

  /// Records frame i of the object: the tracker's result, or none when it has not started (an
  /// object that sat the frame out because its data could not be read -- `problem` says why --
  /// is lost and keeps its last pose); `dataset_mask` is the data's mask, for the IoU of
  /// propagated masks. Returns what was recorded.
  std::optional<bt::TrackResult> record(std::size_t i, std::optional<bt::TrackResult> result, bool started,
                                        std::string problem, double read_ms, const cv::Mat& dataset_mask) {
    const std::string name = sequence_.frameNames()[i];
    const bool readable = problem.empty();
    if (!result && !started) {
      csv_ << name << ",not_started" << std::string(14 + (scored_ ? 2 : 0) + (propagated_ ? 1 : 0), ',') << ','
           << csvField(problem) << '\n';
      return result;
    }
    if (!result) {
      result.emplace();
      result->T_cam_obj = last_pose_;
      result->status = bt::TrackStatus::Lost;
      if (unreadable_++ == 0) first_unreadable_ = problem;
    }
    const bool first = !first_frame_;
    if (first) first_frame_ = i;
    last_pose_ = result->T_cam_obj;
    lost_ += result->status == bt::TrackStatus::Lost;
    by_surface_ += result->surface_only;
    by_flow_ += result->followed > 0;
    ++frames_;
    bt::io::writePose(out_ / "poses" / (name + ".txt"), result->T_cam_obj);
    const auto& t = result->timings;
    csv_ << name << ',' << bt::statusName(result->status) << ',' << result->surface_only << ',' << result->keypoints << ',' << result->followed << ','
         << result->matches << ',' << result->inliers << ',';
    if (result->stability) csv_ << *result->stability;
    csv_ << ',' << read_ms << ',' << t.mask << ',' << t.features << ','
         << t.matching << ',' << t.ransac << ',' << t.graph << ',' << t.solve << ',' << t.total;
    if (scored_) {
      // A frame without an annotated pose is not scored; one that could not be read scores as a failure.
      std::optional<bt::SE3d> true_pose;
      try {
        true_pose = sequence_.groundTruthPose(i, object_);
      } catch (const bt::InputError& error) {
        if (first || strict_) throw;
        ++unscored_;
        if (problem.empty()) problem = std::string(error.what()) + " (frame not scored)";
      }
      csv_ << ',';
      if (true_pose) {
        truth_.push_back(*true_pose);
        estimate_.push_back(readable ? std::optional(result->T_cam_obj) : std::nullopt);
        estimate_unless_lost_.push_back(result->status != bt::TrackStatus::Lost ? std::optional(result->T_cam_obj)
                                                                                : std::nullopt);
        rotation_errors_.push_back(bt::rotationErrorDeg(*true_pose, result->T_cam_obj));
        translation_errors_.push_back(100.0 * bt::translationError(*true_pose, result->T_cam_obj));
        lost_scored_.push_back(result->status == bt::TrackStatus::Lost);
        csv_ << rotation_errors_.back() << ',' << translation_errors_.back();
      } else {
        csv_ << ',';
      }
    }
    if (propagated_) {
      // A frame lost before a mask was made counts as an empty mask.
      const cv::Mat used = result->mask.empty() ? cv::Mat::zeros(sequence_.imageSize(), CV_8UC1) : result->mask;
      const fs::path mask_path = out_ / "masks" / (name + ".png");
      if (!cv::imwrite(mask_path.string(), used)) throw bt::InputError(mask_path, "cannot write image");
      if (!dataset_mask.empty()) mask_ious_.push_back(bt::maskIoU(used > 0, dataset_mask > 0));
      csv_ << ',';
      if (!dataset_mask.empty()) csv_ << mask_ious_.back();
    }
    csv_ << ',' << csvField(problem) << '\n';
    return result;
  }

  /// The object's lines of the summary (the first after `heading`, the others after `prefix`), and its model.
  void report(const std::string& heading, const std::string& prefix, const bt::AnyTracker& tracker) const {
    const char* p = prefix.c_str();
    if (!first_frame_) {
      std::printf("%s no frame has a non-empty mask of this object: not tracked\n", heading.c_str());
      return;
    }
    std::printf("%s %d frames%s, %d lost; poses in %s\n", heading.c_str(), frames_,
                *first_frame_ > 0 ? (" from frame " + sequence_.frameNames()[*first_frame_]).c_str() : "", lost_,
                (out_ / "poses").string().c_str());
    if (unreadable_ > 0)
      std::printf("%s%d of the lost frames could not be read (first: %s); the reasons are in track.csv's problem column\n",
                  p, unreadable_, first_unreadable_.c_str());
    if (unscored_ > 0) std::printf("%s%d frames without an annotated pose were not scored\n", p, unscored_);
    if (by_surface_ > 0)
      std::printf("%s%d frames tracked by the dense term alone, without keypoints (features.detect: on_demand)\n", p,
                  by_surface_);
    if (by_flow_ > 0)
      std::printf("%s%d frames tracked with the last frame's keypoints followed by optical flow (features.follow)\n", p,
                  by_flow_);
    if (!mask_ious_.empty()) {
      double sum = 0.0;
      for (const double iou : mask_ious_) sum += iou;
      std::printf("%spropagated mask IoU against the sequence's masks: mean %.3f, min %.3f over %zu frames\n", p,
                  sum / double(mask_ious_.size()), *std::min_element(mask_ious_.begin(), mask_ious_.end()),
                  mask_ious_.size());
    }
    if (const std::vector<bt::ModelPoint> model = tracker.objectModel(); !model.empty()) {
      bt::io::writeModelPly(out_ / "model.ply", model);
      std::printf("%sobject model: %s (%zu points fused from %zu keyframes)\n", p, (out_ / "model.ply").string().c_str(),
                  model.size(), tracker.keyframeCount());
    }
  }

  /// The object's rows of the score table: its score, with lost frames scored as failures in a
  /// second row where there were any (a lost frame keeps the last pose, which the first row
  /// scores as its estimate); nothing without ground truth and a model.
  void scoreRows(const std::string& label, std::vector<bt::NamedScore>& rows) const {
    if (!scored_ || truth_.empty()) return;
    rows.push_back({label, bt::scoreSequence(model_, truth_, estimate_)});
    if (lost_ > 0) rows.push_back({label + " (lost=failed)", bt::scoreSequence(model_, truth_, estimate_unless_lost_)});
  }

  /// OUT[/object]/errors.png: the errors over the frames, lost frames shaded and left out (the
  /// pose a lost frame keeps is not one the tracker stands behind). Empty without ground truth.
  std::optional<fs::path> plotErrors() const {
    if (!scored_ || truth_.empty()) return std::nullopt;
    const auto unless_lost = [&](std::vector<double> errors) {
      for (std::size_t k = 0; k < errors.size(); ++k)
        if (lost_scored_[k]) errors[k] = std::numeric_limits<double>::quiet_NaN();
      return errors;
    };
    const cv::Mat errors = bt::viz::plotErrors({{"rotation error [deg]", unless_lost(rotation_errors_)},
                                                {"translation error [cm]", unless_lost(translation_errors_)}},
                                               lost_scored_);
    const fs::path plot = out_ / "errors.png";
    if (!cv::imwrite(plot.string(), errors)) throw bt::InputError(plot, "cannot write image");
    return plot;
  }

 private:
  std::string object_;
  fs::path out_;
  const bt::io::RgbdSequence& sequence_;
  bool propagated_, strict_, scored_;
  std::vector<Eigen::Vector3f> model_;
  std::optional<bt::ObjectBox> box_;
  std::ofstream csv_;
  std::optional<std::size_t> first_frame_;  ///< the frame the object started in
  int frames_ = 0, lost_ = 0, unreadable_ = 0, unscored_ = 0, by_surface_ = 0, by_flow_ = 0;
  std::string first_unreadable_;
  bt::SE3d last_pose_;  ///< what a frame the object sits out reports
  std::vector<bt::SE3d> truth_;
  std::vector<std::optional<bt::SE3d>> estimate_;  ///< none: the frame could not be read, a failure for the scores
  std::vector<std::optional<bt::SE3d>> estimate_unless_lost_;  ///< none also where the tracker lost the object
  std::vector<double> rotation_errors_, translation_errors_, mask_ious_;
  std::vector<bool> lost_scored_;  ///< per scored frame, for the error plot
};

/// A frame's files as read ahead (colour, depth, and each object's mask where it has one), with
/// masks given preprocessed ahead over the region their trackers will ask for.
struct FrameData {
  bt::io::FrameAhead frame;
  std::vector<std::optional<cv::Mat>> masks;
};

void run(bt::MultiObjectTracker& tracker, const bt::io::RgbdSequence& sequence, const std::vector<std::string>& objects,
        const Options& options) {
  const bool propagated = options.config.masks == "propagated";
  const bool several = !sequence.objects().empty();
  std::vector<std::unique_ptr<ObjectOutput>> outputs;
  for (const std::string& object : objects)
    outputs.push_back(std::make_unique<ObjectOutput>(object, several ? options.out / object : options.out, sequence, options));
  const std::size_t count = objects.size();
  const bool interactive = isatty(fileno(stderr));
  std::optional<OverlayWriter> overlay;
  if (options.viz) overlay.emplace(options.out, sequence);
  std::vector<double> tracking_ms, read_ms_all, features_ms;
  int tracked_after_first = 0;
  // Files are decoded a few frames ahead on another thread; each frame is preprocessed once, only
  // where the trackers will look (MultiObjectTracker::regionOfInterest). With given masks that
  // region is foretold by the frame's masks (the union of their maskRegion): where tracking is
  // behind reading (ReadAhead's backlog), the reading thread preprocesses it too, and the frame
  // is preprocessed again only where the trackers ask for another region (a tracker's first
  // frame: the whole image).
  const auto preprocess = [&](bt::RawFrame raw, const cv::Rect& region) { return sequence.preprocess(std::move(raw), region); };
  bt::io::ReadAhead<FrameData> files(sequence.size(), [&](std::size_t i, bool backlog) {
    bt::RawFrame raw = sequence.read(i);
    FrameData data;
    if (several) {
      std::vector<std::optional<cv::Mat>> all = sequence.masks(i);
      for (const std::string& object : objects) {
        const auto at = std::find(sequence.objects().begin(), sequence.objects().end(), object);
        data.masks.push_back(std::move(all[std::size_t(at - sequence.objects().begin())]));
      }
    } else {
      data.masks.push_back(raw.mask.empty() ? std::nullopt : std::optional(raw.mask));
    }
    raw.mask = cv::Mat();  // the trackers get their masks beside the frame
    std::optional<cv::Rect> foretold;
    for (const std::optional<cv::Mat>& mask : data.masks) {
      if (!backlog || propagated || !mask || cv::countNonZero(*mask) == 0) continue;
      const cv::Rect own = bt::maskRegion(*mask, raw.color.size());
      foretold = foretold ? *foretold | own : own;
    }
    data.frame = bt::io::frameAhead(std::move(raw), foretold, preprocess);
    return data;
  });
  bt::Stopwatch whole_run, progress;
  double elapsed_ms = 0.0, shown_ms = -1e9;  // since the start, and when the progress line was drawn
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    bt::Stopwatch reading;
    // A frame whose files cannot be read is lost with the reason for every object, which keeps its
    // last pose; an object whose own mask is missing (given masks) sits the frame out likewise.
    // The run goes on; not so for the first frame, nor with --strict.
    std::optional<bt::RgbdFrame> frame;
    std::string frame_problem;
    std::vector<std::string> problems(count);
    std::vector<std::optional<cv::Mat>> given(count);  // what each tracker gets; none: it sits the frame out
    std::vector<cv::Mat> dataset_masks(count);
    try {
      FrameData data = files.next();
      for (std::size_t k = 0; k < count; ++k) {
        dataset_masks[k] = data.masks[k].value_or(cv::Mat());
        if (propagated) {
          given[k] = tracker.started(k) ? cv::Mat() : dataset_masks[k];  // after its start the tracker must not see it
        } else if (data.masks[k] || !tracker.started(k)) {
          given[k] = dataset_masks[k];
        } else {
          const bt::InputError missing(sequence.maskPath(i, objects[k]),
                                       "file not found: tracking with given masks needs a mask for every frame (or use "
                                       "--propagate-masks)");
          if (options.strict || (i == 0 && !several)) throw missing;
          problems[k] = missing.what();
        }
      }
      const cv::Rect region = tracker.regionOfInterest(data.frame.raw.color.size(), given);
      frame = bt::io::preprocessedOver(std::move(data.frame), region, preprocess);
    } catch (const bt::InputError& error) {
      if (i == 0 || options.strict) throw;
      frame_problem = error.what();
    }
    const double read_ms = reading.lap();
    std::vector<std::optional<bt::TrackResult>> results(count);
    bt::Stopwatch tracking;
    if (frame) {
      // An object starts at its annotated pose in that frame where it has ground truth, else at
      // the identity. A start pose that the frame contradicts (checkStartFrame) keeps the object
      // from starting there, with the reason, unless it is the only object's first frame or --strict.
      std::vector<bt::SE3d> start(count);
      for (std::size_t k = 0; k < count; ++k) {
        if (tracker.started(k) || !given[k] || cv::countNonZero(*given[k]) == 0 || !sequence.hasGroundTruth(objects[k]))
          continue;
        start[k] = sequence.groundTruthPose(i, objects[k]);
        bt::RgbdFrame own = *frame;
        own.mask = *given[k];
        try {
          bt::checkStartFrame(own, start[k]);
        } catch (const bt::InputError& error) {
          if (options.strict || (i == 0 && !several)) throw;
          problems[k] = error.what();
          given[k] = std::nullopt;
        }
      }
      results = tracker.track(*frame, given, start);
    }
    const double track_ms = tracking.lap();
    if (i == 0) whole_run.lap();  // the whole run's time counts from the first tracked frame
    std::vector<bt::TrackResult> drawn(count);
    std::vector<DrawnObject> drawn_objects;
    int lost = 0, tracked = 0;
    double features = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      const std::string& problem = frame ? problems[k] : frame_problem;
      const bool started = tracker.started(k);
      if (!results[k] && (started || !problem.empty()) && !options.quiet)
        std::fprintf(stderr, "%sframe %s%s %s: %s\n", interactive ? "\n" : "", sequence.frameNames()[i].c_str(),
                     several ? (" " + objects[k]).c_str() : "", started ? "lost" : "not started", problem.c_str());
      const std::optional<bt::TrackResult> recorded =
          outputs[k]->record(i, std::move(results[k]), started, problem, read_ms, dataset_masks[k]);
      if (recorded) {
        drawn[k] = *recorded;
        features += recorded->timings.features;
        tracked += recorded->status != bt::TrackStatus::Lost;
      }
      lost += outputs[k]->lost();
      drawn_objects.push_back({several ? objects[k] : "", recorded ? &drawn[k] : nullptr, &outputs[k]->box()});
    }
    if (i > 0 && frame) tracking_ms.push_back(track_ms), read_ms_all.push_back(read_ms), features_ms.push_back(features);
    if (i > 0) tracked_after_first += tracked;
    if (frame && overlay) overlay->add(i, *frame, drawn_objects);
    // Progress: on a terminal one line redrawn ten times a second, in a log a line every 50 frames;
    // the rate and the time left from the frames so far.
    elapsed_ms += progress.lap();
    const bool last = i + 1 == sequence.size();
    if (!options.quiet && (interactive ? elapsed_ms - shown_ms >= 100.0 || last : (i + 1) % 50 == 0 || last)) {
      shown_ms = elapsed_ms;
      const double per_frame_ms = elapsed_ms / double(i + 1);
      char state[64];
      if (several) std::snprintf(state, sizeof(state), "%d/%zu objects tracked", tracked, count);
      else std::snprintf(state, sizeof(state), "%-7s  inliers %3d/%-3d", std::string(bt::statusName(drawn[0].status)).c_str(),
                         drawn[0].inliers, drawn[0].matches);
      std::fprintf(stderr, "%sframe %zu/%zu  %s  %5.1f ms  |  %.1f fps, %d lost, %.0f s left%s", interactive ? "\r" : "", i + 1,
                   sequence.size(), state, track_ms, 1000.0 / per_frame_ms, lost,
                   per_frame_ms * double(sequence.size() - i - 1) / 1000.0, interactive ? "   " : "\n");
    }
  }
  const double run_ms = whole_run.lap();  // frames 1 .. n-1 with writing the results
  if (!options.quiet && interactive) std::fprintf(stderr, "\n");
  const std::string sequence_name = options.sequence.string();
  for (std::size_t k = 0; k < count; ++k)
    outputs[k]->report(several ? "[" + objects[k] + "]" : sequence_name + ":", several ? "[" + objects[k] + "] " : "",
                       tracker.tracker(k));
  // Rates only where something was tracked: the time of frames that were all lost is no frame rate.
  if (sequence.size() > 1 && tracked_after_first == 0) {
    std::printf("no frame after the first was tracked: no frame rate\n");
  } else if (!tracking_ms.empty()) {
    const double median_ms = median(tracking_ms);
    std::printf("median per frame: %.1f ms tracking%s (%.1f fps; keypoint detection %.1f ms of it), %.1f ms waiting "
                "for its files and preprocessing it; per stage in track.csv\n",
                median_ms, several ? (" " + std::to_string(count) + " objects").c_str() : "", 1000.0 / median_ms,
                median(features_ms), median(read_ms_all));
    const double per_frame = run_ms / double(sequence.size() - 1);
    std::printf("whole run after the first frame: %.1f ms per frame from the files to the poses written (%.1f fps)\n",
                per_frame, 1000.0 / per_frame);
  }
  std::vector<bt::NamedScore> rows;
  for (std::size_t k = 0; k < count && !options.no_score; ++k)
    outputs[k]->scoreRows(several ? objects[k] : options.sequence.filename().string(), rows);
  if (!rows.empty()) {
    std::printf("%s", bt::formatScoreTable(rows, bt::MeanRow::Omit).c_str());  // views of one run, objects apart: no mean
    for (const bt::NamedScore& row : rows)
      if (row.sequence.find(" (lost=failed)") == std::string::npos)
        std::printf("final-frame ADD%s %.2f cm\n", several ? (" " + row.sequence).c_str() : "", row.score.final_add_cm);
  }
  if (overlay) {
    std::printf("overlay: %s\n", overlay->finish().c_str());
    for (std::size_t k = 0; k < count; ++k)
      if (const auto plot = outputs[k]->plotErrors()) std::printf("error plot: %s\n", plot->string().c_str());
  }
}

/// Writes a small text file; a failure to do so is left to the run's own output checks.
void writeText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace

int main(int argc, char** argv) {
  bt::keepFreedFrameMemory();  // frames allocate image-sized buffers: no page faults for each
  Options options;
  fs::path incomplete;  // OUT/INCOMPLETE once the output exists
  bool print_config = false, print_config_table = false, propagate_masks = false, gpu = false;
  std::string sequence, out, config_file;
  // Options that set a configuration key: applied over --config in this order (each may be given once).
  std::vector<std::pair<std::string, std::string>> overrides = {
      {"--tracker", ""}, {"--features", ""}, {"--depth-scale", ""}, {"--min-inliers", ""}, {"--inlier-mm", ""}, {"--sensor", ""}};
  const auto value_of = [&](const std::string& option) -> std::string& {
    return std::find_if(overrides.begin(), overrides.end(), [&](const auto& entry) { return entry.first == option; })->second;
  };
  bt::examples::CommandLine command_line(
      "Tracks the 6D pose of an object through an RGB-D sequence (BundleTrack, online and causal) from its\n"
      "first frame's mask and pose; writes OUT/poses/<frame>.txt (4x4 T_cam_obj), OUT/track.csv and\n"
      "OUT/model.ply, and scores the poses where the sequence has ground truth.",
      "bundletrack_track");
  command_line.add_option("--sequence", sequence, "the sequence directory (YCBInEOAT or TUM RGB-D layout)")->type_name("DIR");
  command_line.add_option("--out", out, "the output directory (created; its poses/ and masks/ are replaced)")->type_name("DIR");
  command_line.add_option("--config", config_file, "YAML settings over the defaults (see --print-config); options below override it")
      ->type_name("FILE");
  command_line.add_flag("--print-config", print_config, "print the effective configuration as YAML and exit");
  command_line.add_flag("--print-config-table", print_config_table, "print every setting with its default as a Markdown table and exit");
  command_line.add_option("--features", value_of("--features"), "sift | orb | akaze (sift)")->type_name("F");
  command_line.add_option("--tracker", value_of("--tracker"),
                          "full: pose graph over keyframes (paper IV) | coarse: frame-to-frame RANSAC only (full)")
      ->type_name("T");
  command_line.add_option("--depth-scale", value_of("--depth-scale"),
                          "metres per unit of the depth images (the layout's: 0.001 YCBInEOAT, 1/5000 TUM)")
      ->type_name("S");
  command_line.add_option("--min-inliers", value_of("--min-inliers"), "fewest RANSAC inliers that count as a pose; fewer: the frame is lost (5)")
      ->type_name("N");
  command_line.add_option("--inlier-mm", value_of("--inlier-mm"), "RANSAC inlier distance in millimetres (5; widened by the sensor's noise)")
      ->type_name("D");
  command_line.add_option("--sensor", value_of("--sensor"),
                          "structured_light (Kinect v1, Xtion) | active_stereo (RealSense D4xx) |\n"
                          "time_of_flight (Azure Kinect): the depth noise every depth tolerance widens\n"
                          "with (sensor.model; structured_light); loads the preset's numbers over any\n"
                          "sensor.* of --config (refine a preset with sensor.* keys in the file)")
      ->type_name("S");
  command_line.add_flag("--gpu", gpu, "matching, dense term, PCG and RANSAC on a CUDA device (compute.device: gpu;\n"
                                      "needs a build with the CUDA backend and a GPU; keypoints stay on the CPU)");
  command_line.add_flag("--propagate-masks", propagate_masks,
                        "the tracker gets only the first frame's mask and follows the object from it\n"
                        "(masks.source: propagated); later masks, where the sequence has them, are\n"
                        "read only to report each propagated mask's IoU in track.csv and a summary;\n"
                        "the masks used go to OUT/masks/<frame>.png; chosen by itself, with a note,\n"
                        "where every object has a mask for one frame only (masks/ with the first frame's\n"
                        "mask alone; of several objects, one mask of each)");
  command_line.add_flag("--viz", options.viz, "write OUT/overlay.mp4 (pose axes, object box, mask outline per frame; an image\n"
                                              "strip OUT/overlay_strip.png always, and in place of the video where no encoder\n"
                                              "is available) and, with ground truth, OUT/errors.png (errors over time)");
  command_line.add_flag("--strict", options.strict, "a later frame that cannot be read (file missing or undecodable, depth without\n"
                                                    "a reading, no mask with given masks, no annotated pose) stops the run; by\n"
                                                    "default it is reported lost with the reason (track.csv: problem) and the run\n"
                                                    "goes on, the frame scored as a failure (without an annotated pose: not scored);\n"
                                                    "likewise an object's start pose that its frame contradicts (checkStartFrame),\n"
                                                    "which by default keeps that object from starting there");
  command_line.add_option("--objects", options.objects, "a sequence of several objects (masks/<object>/<frame>.png, one folder per\n"
                                                        "object, or label images labels/<frame>.png named by labels/objects.txt;\n"
                                                        "annotated_poses/<object>/ and model/<object>/ likewise): the objects\n"
                                                        "to track, names separated by commas, or all (all). Each is tracked by its own\n"
                                                        "tracker from the first frame with a non-empty mask of it, at its annotated pose\n"
                                                        "there (else the identity), the frames read and preprocessed once for all of\n"
                                                        "them; the outputs go to OUT/<object>/ (poses/, track.csv, model.ply,\n"
                                                        "errors.png), the overlay shows them all")
      ->type_name("LIST");
  command_line.add_flag("--quiet", options.quiet, "no progress line");
  command_line.add_flag("--no-score", options.no_score,
                        "no ADD / ADD-S table at the end (track.csv keeps each frame's errors; bundletrack_eval\n"
                        "scores the poses later): the run's time is then files to poses alone");
  command_line.parseOrExit(argc, argv);
  if (print_config_table) {
    std::cout << bt::settingsTable();
    return 0;
  }
  options.sequence = sequence, options.out = out, options.config_file = config_file;
  if (propagate_masks) overrides.emplace_back("--propagate-masks", "");
  if (gpu) overrides.emplace_back("--gpu", "");
  try {
    if (!options.config_file.empty()) options.config = bt::loadConfig(options.config_file);
    auto& config = options.config;
    for (const auto& [option, text] : overrides) {
      if (text.empty() && option != "--propagate-masks" && option != "--gpu") continue;  // not given
      if (option == "--tracker") config.tracker = text;
      else if (option == "--features") config.features = text;
      else if (option == "--depth-scale") bt::setNumber(config, "depth.scale", number(command_line, option, text), option + " " + text);
      else if (option == "--min-inliers") bt::setNumber(config, "ransac.min_inliers", number(command_line, option, text), option + " " + text);
      else if (option == "--inlier-mm")
        bt::setNumber(config, "ransac.inlier_distance", number(command_line, option, text) * 1e-3, option + " " + text);
      else if (option == "--sensor") setChoice(command_line, config, "sensor.model", option, text);
      else if (option == "--propagate-masks") config.masks = "propagated";
      else if (option == "--gpu") config.device = "gpu";
    }
    bt::requireConsistent(config, options.config_file.empty() ? fs::path("the options") : options.config_file);
    if (print_config) {
      std::cout << bt::printConfig(config);
      return 0;
    }
    if (options.sequence.empty() || options.out.empty()) command_line.fail("--sequence and --out are required");
    prepareOutput(options.out, {});
    const bt::io::RgbdSequence sequence(options.sequence, config.sequence);
    for (const std::string& caution : sequence.warnings()) std::cerr << "warning: " << caution << '\n';
    const std::vector<std::string> objects = chosenObjects(sequence, options.objects);
    if (config.masks == "given" && oneMaskEach(sequence, objects)) {
      config.masks = "propagated";
      std::cerr << "note: " << sequence.objectList().string()
                << (sequence.objects().empty() ? " has a mask for the first frame only"
                                               : ": each object has a mask for one frame only")
                << ": the masks are propagated from it (masks.source: propagated, as --propagate-masks)\n";
    }
    std::vector<fs::path> folders = {"poses"};
    if (config.masks == "propagated") folders.push_back("masks");
    for (const std::string& object : objects) prepareOutput(options.out / object, folders);
    // Until the run ends well, OUT says that what it holds is partial, and after an error why.
    incomplete = options.out / "INCOMPLETE";
    writeText(incomplete, "bundletrack_track has not finished: the outputs here cover only the frames written so far\n");
    const bt::PinholeCameraf camera = sequence.camera().cast<float>();
    bt::MultiObjectTracker tracker(objects.size(), [&] { return bt::makeTracker(config, camera); });
    run(tracker, sequence, objects, options);
    fs::remove(incomplete);
    return 0;
  } catch (const std::invalid_argument& error) {
    command_line.fail(error.what());
  } catch (const std::exception& error) {
    std::cerr << "\nerror: " << error.what() << '\n';
    if (!incomplete.empty())
      writeText(incomplete, std::string("bundletrack_track stopped with an error; the outputs here are partial:\n") +
                                error.what() + '\n');
    return 1;
  }
}
