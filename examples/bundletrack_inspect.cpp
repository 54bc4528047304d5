// bundletrack_inspect --sequence DIR [--depth-scale S] [--overlay DIR [--every N]] (--help: the options)
// Loads and preprocesses every frame of a YCBInEOAT-layout sequence and prints what the tracker
// will see: object mask area, how much of it has depth before and after filtering, normals,
// object depth and the preprocessing time per frame. --overlay writes every N-th frame with the
// annotated pose's axes and the mask outline, to check a dataset's conventions by eye.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

#include "command_line.hpp"

#include "bundletrack/io/rgbd_sequence.hpp"
#include "bundletrack/viz/overlay.hpp"

namespace bt = bundletrack;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void writeOverlay(const std::filesystem::path& dir, const bt::io::RgbdSequence& sequence,
                  const bt::RgbdFrame& frame, std::size_t i) {
  std::filesystem::create_directories(dir);
  cv::Mat image = frame.color.clone();
  if (!frame.mask.empty()) bt::viz::drawMaskContour(image, frame.mask, {0, 255, 255});
  if (sequence.hasGroundTruth()) bt::viz::drawAxes(image, sequence.camera(), sequence.groundTruthPose(i), 0.08);
  const auto path = dir / (frame.name + ".png");
  if (!cv::imwrite(path.string(), image)) throw bt::InputError(path, "cannot write image");
}

}  // namespace

int main(int argc, char** argv) {
  std::string sequence_dir, overlay_dir;
  int every = 10;
  bt::io::SequenceSettings settings;
  bt::examples::CommandLine command_line(
      "Loads and preprocesses every frame of a sequence and prints what the tracker will see: mask area,\n"
      "depth before and after filtering, normals, object depth, preprocessing time per frame.",
      "bundletrack_inspect");
  command_line.add_option("--sequence", sequence_dir, "the sequence directory (YCBInEOAT or TUM RGB-D layout)")
      ->type_name("DIR")
      ->required();
  command_line.add_option("--depth-scale", settings.depth_scale, "metres per unit of the depth images (default: the layout's)")
      ->type_name("S")
      ->check(bt::examples::positive());
  command_line.add_option("--overlay", overlay_dir, "write frames with the annotated pose's axes and the mask outline to DIR")
      ->type_name("DIR");
  command_line.add_option("--every", every, "with --overlay: every N-th frame")->capture_default_str()->check(bt::examples::wholeAtLeast(1));
  command_line.parseOrExit(argc, argv);

  try {
    const bt::io::RgbdSequence sequence(sequence_dir, settings);
    for (const std::string& caution : sequence.warnings()) std::printf("warning    %s\n", caution.c_str());
    const auto& K = sequence.camera();
    std::printf("sequence   %s\nframes     %zu (%s .. %s), %dx%d\nintrinsics fx %.2f fy %.2f cx %.2f cy %.2f\n",
                sequence_dir.c_str(), sequence.size(), sequence.frameNames().front().c_str(),
                sequence.frameNames().back().c_str(), sequence.imageSize().width, sequence.imageSize().height, K.fx,
                K.fy, K.cx, K.cy);
    std::printf("truth      %s, model %s\n", sequence.hasGroundTruth() ? "annotated poses" : "none",
                sequence.hasModel() ? (std::to_string(sequence.modelPoints().size()) + " points").c_str() : "none");

    std::vector<double> area, raw_valid, kept, with_normal, object_depth, milliseconds;
    std::size_t masked_frames = 0;
    for (std::size_t i = 0; i < sequence.size(); ++i) {
      const auto start = std::chrono::steady_clock::now();
      const bt::RgbdFrame frame = sequence.frame(i);
      milliseconds.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      if (!overlay_dir.empty() && i % std::size_t(every) == 0) writeOverlay(overlay_dir, sequence, frame, i);
      if (frame.mask.empty()) continue;
      ++masked_frames;
      const cv::Mat raw = sequence.rawDepth(i);
      const double n = std::max(1, cv::countNonZero(frame.mask));
      area.push_back(n);
      raw_valid.push_back(cv::countNonZero((raw > 0) & frame.mask) / n);
      kept.push_back(cv::countNonZero((frame.depth > 0) & frame.mask) / n);
      std::vector<cv::Mat> normal_channels;
      cv::split(frame.normals, normal_channels);
      with_normal.push_back(cv::countNonZero((normal_channels[2] != 0) & frame.mask) / n);
      std::vector<double> depths;
      for (int v = 0; v < frame.depth.rows; ++v)
        for (int u = 0; u < frame.depth.cols; ++u)
          if (frame.mask.at<uchar>(v, u) && frame.depth.at<float>(v, u) > 0) depths.push_back(frame.depth.at<float>(v, u));
      object_depth.push_back(median(depths));
    }
    std::printf("masks      %zu of %zu frames\n", masked_frames, sequence.size());
    std::printf("per frame (median)   mask %.0f px | depth in mask: raw %.1f%%, after filtering %.1f%% | "
                "normals %.1f%% | object depth %.3f m | preprocessing %.1f ms\n",
                median(area), 100 * median(raw_valid), 100 * median(kept), 100 * median(with_normal),
                median(object_depth), median(milliseconds));
  } catch (const bt::InputError& error) {
    std::cerr << "error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
