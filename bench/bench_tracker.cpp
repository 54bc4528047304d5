// bench_tracker [--sequence DIR ...] [--frames N] [--memory-every N] [--features F] [--gpu]
// Runs the default tracker (with --features orb|akaze: that detector instead of SIFT; built by
// makeTracker) on each sequence (or on a synthetic one rendered in memory) as bundletrack_track
// does: files decoded a few frames ahead on another thread (io::ReadAhead), each frame
// preprocessed inside the tracker's region of interest. Prints, per stage, the median and 90th
// percentile of the milliseconds per frame and the share of the median frame; the whole run's
// milliseconds per frame (files to poses) and, for sequences, the time to merely decode the same
// files with OpenCV (colour, depth, mask; one pass before the run) and the ratio of the two.
// --memory-every N also prints, every N frames, the keyframes in the pool, the process's resident
// and peak resident memory (Linux /proc/self/status) and the mean milliseconds per frame
// (preprocessing and tracking) over those N frames.
// --gpu (builds with BUNDLETRACK_CUDA) also runs the tracker composed of the GPU policies on the
// same frames and prints both per-stage medians side by side with the GPU/CPU ratio.
#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "command_line.hpp"

#include "bundletrack/core/frame_memory.hpp"
#include "bundletrack/core/image_region.hpp"
#include "bundletrack/io/frame_ahead.hpp"
#include "bundletrack/io/read_ahead.hpp"
#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/runtime/make_tracker.hpp"
#include "bundletrack/synth/synthetic_sequence.hpp"
#include "bundletrack/tracking/stopwatch.hpp"

namespace bt = bundletrack;

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(q * double(v.size() - 1) + 0.5))];
}

struct Stages {
  std::vector<double> read, mask, features, matching, ransac, graph, solve, total;
  double whole_run_ms = 0.0;  ///< wall time of frames 1 .. n-1, reading and preprocessing included
  void add(double read_ms, const bt::StageTimings& t) {
    read.push_back(read_ms), mask.push_back(t.mask), features.push_back(t.features), matching.push_back(t.matching);
    ransac.push_back(t.ransac), graph.push_back(t.graph), solve.push_back(t.solve), total.push_back(t.total);
  }
};

void report(const std::string& name, const Stages& s) {
  const double median_total = percentile(s.total, 0.5);
  std::printf("\n%s: %zu frames (read = waiting for the decoded files and preprocessing the region of interest, "
              "outside the tracker's total)\n%-10s %10s %10s %9s\n",
              name.c_str(), s.total.size(), "stage", "median ms", "p90 ms", "of total");
  const std::pair<const char*, const std::vector<double>*> rows[] = {
      {"read", &s.read},         {"mask", &s.mask},   {"features", &s.features}, {"matching", &s.matching},
      {"ransac", &s.ransac},     {"graph", &s.graph}, {"solve", &s.solve},       {"total", &s.total}};
  for (const auto& [label, values] : rows)
    std::printf("%-10s %10.2f %10.2f %7.1f%%\n", label, percentile(*values, 0.5), percentile(*values, 0.9),
                100.0 * percentile(*values, 0.5) / median_total);
  double sum = 0.0;
  for (const double t : s.total) sum += t;
  const double whole = s.whole_run_ms / double(s.total.size());
  std::printf("frames per second: %.1f tracking; whole run %.2f ms per frame (%.1f fps) from the files to the poses\n",
              1000.0 * double(s.total.size()) / sum, whole, 1000.0 / whole);
}

/// VmRSS and VmHWM of this process in MiB (0 where /proc is not available).
std::pair<double, double> residentMemoryMiB() {
  std::ifstream status("/proc/self/status");
  double rss = 0.0, peak = 0.0;
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) rss = std::stod(line.substr(6)) / 1024.0;
    if (line.rfind("VmHWM:", 0) == 0) peak = std::stod(line.substr(6)) / 1024.0;
  }
  return {rss, peak};
}

/// A frame as decoded (or rendered), preprocessed ahead over its mask's region (the tracker's once
/// started: frameAhead), and its pose where known.
struct Input {
  bt::io::FrameAhead frame;
  bt::SE3d pose;
};

/// makeFrame with the default settings, as the benchmark's tracker preprocesses.
auto preprocessor(const bt::PinholeCameraf& camera) {
  return [camera](bt::RawFrame raw, const cv::Rect& region) { return bt::makeFrame(std::move(raw), camera, {}, region); };
}

/// On the reading thread: the frame, preprocessed over its mask's region where it has a mask and
/// tracking is behind reading (ReadAhead's backlog), as bundletrack_track does.
bt::io::FrameAhead ahead(bt::RawFrame raw, const bt::PinholeCameraf& camera, bool backlog) {
  const std::optional<cv::Rect> foretold =
      !backlog || raw.mask.empty() ? std::nullopt : std::optional(bt::maskRegion(raw.mask, raw.color.size()));
  return bt::io::frameAhead(std::move(raw), foretold, preprocessor(camera));
}

template <typename ReadAt>
Stages track(bt::AnyTracker& tracker, const bt::PinholeCameraf& camera, std::size_t frames, int memory_every,
             ReadAt&& read_at) {
  Stages stages;
  if (memory_every > 0)
    std::printf("%8s %10s %12s %13s %6s %11s\n", "frame", "keyframes", "resident MiB", "peak MiB", "lost", "ms / frame");
  int lost = 0;
  double interval_ms = 0.0;  // preprocessing and tracking since the last memory line
  std::size_t interval_frames = 0;
  bt::io::ReadAhead<Input> inputs(frames, read_at);
  bt::Stopwatch whole_run;
  for (std::size_t i = 0; i < frames; ++i) {
    bt::Stopwatch read;
    Input input = inputs.next();
    const cv::Rect region = tracker.regionOfInterest(input.frame.raw.color.size(), input.frame.raw.mask);
    const bt::RgbdFrame frame = bt::io::preprocessedOver(std::move(input.frame), region, preprocessor(camera));
    const double read_ms = read.lap();
    const bt::TrackResult result = i == 0 ? tracker.initialize(frame, input.pose) : tracker.track(frame);
    lost += result.status == bt::TrackStatus::Lost;
    if (i == 0) whole_run.lap();
    if (i > 0) stages.add(read_ms, result.timings);
    interval_ms += read_ms + result.timings.total;
    ++interval_frames;
    if (memory_every > 0 && ((i + 1) % std::size_t(memory_every) == 0 || i + 1 == frames)) {
      const auto [rss, peak] = residentMemoryMiB();
      std::printf("%8zu %10zu %12.1f %13.1f %6d %11.2f\n", i + 1, tracker.keyframeCount(), rss, peak, lost,
                  interval_ms / double(interval_frames));
      interval_ms = 0.0;
      interval_frames = 0;
      std::fflush(stdout);
    }
  }
  stages.whole_run_ms = whole_run.lap();
  return stages;
}

/// Milliseconds per frame to decode a sequence's files with OpenCV alone (colour, depth, mask).
double decodeOnlyMs(const bt::io::RgbdSequence& sequence, std::size_t frames) {
  bt::Stopwatch clock;
  for (std::size_t i = 0; i < frames; ++i) {
    const std::pair<std::filesystem::path, int> files[] = {{sequence.colorPath(i), cv::IMREAD_COLOR},
                                                           {sequence.depthPath(i), cv::IMREAD_UNCHANGED},
                                                           {sequence.maskPath(i), cv::IMREAD_GRAYSCALE}};
    for (const auto& [path, flags] : files)
      if (std::filesystem::exists(path) && cv::imread(path.string(), flags).empty())
        throw bt::InputError(path, "cannot decode image");
  }
  return clock.lap() / double(frames);
}

/// Per-stage medians of two runs on the same frames, and their ratio.
void compare(const Stages& cpu, const Stages& gpu) {
  std::printf("\n%-10s %12s %12s %10s\n", "stage", "CPU ms", "GPU ms", "GPU/CPU");
  const std::pair<const char*, std::pair<const std::vector<double>*, const std::vector<double>*>> rows[] = {
      {"mask", {&cpu.mask, &gpu.mask}},       {"features", {&cpu.features, &gpu.features}},
      {"matching", {&cpu.matching, &gpu.matching}}, {"ransac", {&cpu.ransac, &gpu.ransac}},
      {"graph", {&cpu.graph, &gpu.graph}},    {"solve", {&cpu.solve, &gpu.solve}},
      {"total", {&cpu.total, &gpu.total}}};
  for (const auto& [label, values] : rows) {
    const double c = percentile(*values.first, 0.5), g = percentile(*values.second, 0.5);
    std::printf("%-10s %12.2f %12.2f %10.2f\n", label, c, g, c > 0.0 ? g / c : 0.0);
  }
}

struct Options {
  std::vector<std::string> sequences;
  int frames = 150, memory_every = 0;
  std::string features = "sift";
  bool gpu = false;
};

/// The default tracker with the --features detector on the frames, and with --gpu the
/// GPU-composed one as well. decode_ms: the files' decoding alone, per frame (0: not measured).
template <typename ReadAt>
void run(const std::string& name, const bt::PinholeCameraf& camera, std::size_t frames, const Options& options,
         ReadAt&& read_at, double decode_ms = 0.0) {
  bt::Config config;
  config.features = options.features;
  const std::unique_ptr<bt::AnyTracker> cpu_tracker = bt::makeTracker(config, camera);
  config.device = "gpu";
  const std::unique_ptr<bt::AnyTracker> gpu_tracker = options.gpu ? bt::makeTracker(config, camera) : nullptr;
  const std::string label = name + " [" + options.features + "]";
  const Stages cpu = track(*cpu_tracker, camera, frames, options.memory_every, read_at);
  report(label, cpu);
  if (decode_ms > 0.0)
    std::printf("decoding the files alone (OpenCV: colour, depth, mask): %.2f ms per frame; whole run / decoding = %.2f\n",
                decode_ms, cpu.whole_run_ms / double(cpu.total.size()) / decode_ms);
  if (!gpu_tracker) return;
  const Stages gpu = track(*gpu_tracker, camera, frames, 0, read_at);
  report(label + " (GPU policies: cuda::PCG, cuda::GpuMatched, cuda::DensePointToPlane, cuda::Ransac)", gpu);
  compare(cpu, gpu);
}

}  // namespace

int main(int argc, char** argv) {
  bt::keepFreedFrameMemory();  // frames allocate image-sized buffers: no page faults for each
  Options options;
  bt::examples::CommandLine command_line(
      "The default tracker's time per stage (medians and 90th percentiles) on sequences from files, or on\n"
      "the synthetic hand-held box rendered in memory.",
      "bench_tracker");
  command_line.add_option("--sequence", options.sequences, "a sequence directory (repeatable; none: the synthetic box)")
      ->type_name("DIR");
  command_line.add_option("--frames", options.frames, "frames of the synthetic box")->capture_default_str()->check(bt::examples::wholeAtLeast(1));
  command_line.add_option("--memory-every", options.memory_every, "report resident memory every N frames (0: no memory report)")
      ->capture_default_str()
      ->check(bt::examples::wholeAtLeast(0));
  command_line.add_option("--features", options.features, "sift | orb | akaze")
      ->capture_default_str()
      ->check(CLI::IsMember({"sift", "orb", "akaze"}));
  command_line.add_flag("--gpu", options.gpu, "also the GPU-composed tracker on the same frames");
  command_line.parseOrExit(argc, argv);
  const int frames = options.frames;
  try {
    if (options.sequences.empty()) {
      bt::synth::SyntheticSequenceSettings settings;
      settings.frames = frames;
      const bt::synth::SyntheticScene scene(settings);
      const auto camera = settings.camera.cast<float>();
      run("synthetic hand-held box (rendering counted as reading)", camera, std::size_t(frames), options,
          [&](std::size_t i, bool backlog) {
            const auto f = scene.frame(int(i));
            return Input{ahead({std::to_string(i), f.color, f.depth, f.mask}, camera, backlog), f.T_cam_obj};
          });
    }
    for (const auto& dir : options.sequences) {
      const bt::io::RgbdSequence sequence(dir);
      const auto camera = sequence.camera().cast<float>();
      const double decode_ms = decodeOnlyMs(sequence, sequence.size());
      run(
          dir, camera, sequence.size(), options,
          [&](std::size_t i, bool backlog) {
            return Input{ahead(sequence.read(i), camera, backlog),
                         sequence.hasGroundTruth() ? sequence.groundTruthPose(i) : bt::SE3d()};
          },
          decode_ms);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
  return 0;
}
