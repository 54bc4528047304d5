#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bundletrack/core/error.hpp"
#include "bundletrack/io/file_access.hpp"

namespace bundletrack::io {

/// How a sequence folder lists its frames.
enum class Layout {
  Auto,  ///< TUM when rgb.txt and depth.txt exist, else YCBInEOAT
  YcbInEoat,  ///< rgb/<name>.png|jpg and depth/<name>.png, frames in name order
  Tum,  ///< TUM RGB-D: rgb.txt and depth.txt list timestamped images, associated by time
};

/// A layout's frames: their names (the colour images' stems: masks/, annotated_poses/ and the
/// output poses use them), colour and depth files (an empty depth path: the frame has none), and
/// the layout's depth unit (metres per unit of its 16-bit depth images).
struct FrameFiles {
  std::vector<std::string> names;
  std::vector<std::filesystem::path> color, depth;
  std::vector<std::string> missing_depth;  ///< per frame: why it has no depth file ("" if it has)
  double depth_unit = 0.001;
};

/// YCBInEOAT: the colour images rgb/*.png, *.jpg in name order (numeric names compared as
/// numbers), each with depth/<name>.png, in millimetres. Throws InputError without any image, or
/// for two images of one name.
inline FrameFiles ycbineoatFrames(const std::filesystem::path& root) {
  const auto numericName = [](const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
  };
  const auto dir = root / "rgb";
  if (!std::filesystem::is_directory(dir)) throw InputError(dir, "directory not found");
  std::vector<std::filesystem::path> found;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) found.push_back(entry.path());
  }
  if (found.empty()) throw InputError(dir, "no .png or .jpg colour images");
  std::sort(found.begin(), found.end(), [&](const std::filesystem::path& a, const std::filesystem::path& b) {
    const std::string x = a.stem().string(), y = b.stem().string();
    if (numericName(x) && numericName(y) && x.size() != y.size()) return x.size() < y.size();
    return x < y;
  });
  FrameFiles frames;
  for (const std::filesystem::path& file : found) {
    const std::string name = file.stem().string();
    if (!frames.names.empty() && frames.names.back() == name)
      throw InputError(dir, "two colour images share the name '" + name + "'");
    frames.names.push_back(name);
    frames.color.push_back(file);
    frames.depth.push_back(root / "depth" / (name + ".png"));
    frames.missing_depth.emplace_back();
  }
  return frames;
}

/// One line of a TUM list file: a timestamp (seconds) and a file relative to the folder.
struct TimedFile {
  double time;
  std::filesystem::path file;
};

/// Reads rgb.txt or depth.txt: lines "timestamp file", '#' comments and blank lines skipped.
inline std::vector<TimedFile> readTimedFiles(const std::filesystem::path& list) {
  std::ifstream in = openForReading(list);
  std::vector<TimedFile> files;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::string time, file;
    if (!(fields >> time)) continue;
    double seconds = 0.0;
    try {
      std::size_t used = 0;
      seconds = std::stod(time, &used);
      if (used != time.size() || !std::isfinite(seconds)) throw std::invalid_argument(time);
    } catch (const std::exception&) {
      throw InputError(list, "line " + std::to_string(number) + ": '" + time + "' is not a timestamp");
    }
    if (!(fields >> file)) throw InputError(list, "line " + std::to_string(number) + ": a timestamp without a file");
    files.push_back({seconds, list.parent_path() / file});
  }
  if (files.empty()) throw InputError(list, "lists no images");
  std::stable_sort(files.begin(), files.end(), [](const TimedFile& a, const TimedFile& b) { return a.time < b.time; });
  return files;
}

/// TUM RGB-D: the colour images of rgb.txt in time order, each with the depth image of depth.txt
/// nearest in time within max_time_difference seconds, every depth image used once (nearest
/// pairs first, as the benchmark's associate.py); depth in 1/5000 m. A colour image without such
/// a depth image stays a frame without depth (read() says so: a lost frame, the run goes on).
inline FrameFiles tumFrames(const std::filesystem::path& root, double max_time_difference) {
  const std::vector<TimedFile> colors = readTimedFiles(root / "rgb.txt"), depths = readTimedFiles(root / "depth.txt");
  struct Pair {
    double difference;
    std::size_t color, depth;
  };
  std::vector<Pair> pairs;
  for (std::size_t c = 0; c < colors.size(); ++c) {
    // Depth images within the window, found by bisection: the lists are sorted by time.
    auto d = std::lower_bound(depths.begin(), depths.end(), colors[c].time - max_time_difference,
                              [](const TimedFile& f, double t) { return f.time < t; });
    for (; d != depths.end() && d->time <= colors[c].time + max_time_difference; ++d)
      pairs.push_back({std::abs(d->time - colors[c].time), c, std::size_t(d - depths.begin())});
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.difference < b.difference; });
  std::vector<long> depth_of(colors.size(), -1);
  std::vector<bool> depth_used(depths.size(), false);
  for (const Pair& p : pairs)
    if (depth_of[p.color] < 0 && !depth_used[p.depth]) depth_of[p.color] = long(p.depth), depth_used[p.depth] = true;
  FrameFiles frames;
  frames.depth_unit = 1.0 / 5000.0;
  for (std::size_t c = 0; c < colors.size(); ++c) {
    const std::string name = colors[c].file.stem().string();
    if (!frames.names.empty() && frames.names.back() == name)
      throw InputError(root / "rgb.txt", "two colour images share the name '" + name + "'");
    frames.names.push_back(name);
    frames.color.push_back(colors[c].file);
    frames.depth.push_back(depth_of[c] >= 0 ? depths[std::size_t(depth_of[c])].file : std::filesystem::path());
    frames.missing_depth.push_back(depth_of[c] >= 0 ? std::string()
                                                    : "no depth image in depth.txt within " +
                                                          std::to_string(int(std::lround(1000 * max_time_difference))) +
                                                          " ms of this colour image (sequence.max_time_difference)");
  }
  return frames;
}

/// The frames of `root` in `layout` (Auto: TUM when rgb.txt and depth.txt exist).
inline FrameFiles frameFiles(const std::filesystem::path& root, Layout layout, double max_time_difference) {
  if (layout == Layout::Auto)
    layout = std::filesystem::is_regular_file(root / "rgb.txt") && std::filesystem::is_regular_file(root / "depth.txt")
                 ? Layout::Tum
                 : Layout::YcbInEoat;
  return layout == Layout::Tum ? tumFrames(root, max_time_difference) : ycbineoatFrames(root);
}

}  // namespace bundletrack::io
