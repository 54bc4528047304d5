#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/error.hpp"
#include "bundletrack/io/file_access.hpp"
#include "bundletrack/io/image_files.hpp"

namespace bundletrack::io {

/// A label image of several objects, one per frame: each pixel holds the label of the object it
/// shows, 0 where none. Single-channel 8 or 16 bits (PNG); returned as decoded.
inline cv::Mat labelsFromImage(const cv::Mat& raw, const std::filesystem::path& path) {
  if (raw.channels() != 1 || (raw.depth() != CV_8U && raw.depth() != CV_16U))
    throw InputError(path, "a label image must have one channel of 8 or 16 bits, got " + describeImageType(raw));
  return raw;
}

/// The mask (CV_8UC1, 0 or 255) of the pixels of `labels` equal to `label`.
inline cv::Mat labelMask(const cv::Mat& labels, int label) {
  cv::Mat mask;
  cv::compare(labels, cv::Scalar(label), mask, cv::CMP_EQ);
  return mask;
}

/// The objects of the label images, in the order listed: one line per object, "<label> <name>",
/// the label an integer from 1 to 65535, the name letters, digits, '_', '-' and '.' (it names the
/// object's folders: annotated_poses/<name>/, model/<name>/, the tracker's OUT/<name>/); '#'
/// starts a comment, blank lines are skipped. A label or name given twice, or no object, is an
/// error naming the line.
inline std::vector<std::pair<int, std::string>> parseLabelNames(std::istream& in, const std::filesystem::path& path) {
  std::vector<std::pair<int, std::string>> objects;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::istringstream fields(line);
    std::string label_text, name, extra;
    if (!(fields >> label_text)) continue;
    const std::string at = "line " + std::to_string(number) + ": ";
    if (!(fields >> name) || (fields >> extra)) throw InputError(path, at + "expected '<label> <name>'");
    std::size_t used = 0;
    int label = 0;
    try {
      label = std::stoi(label_text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != label_text.size() || label < 1 || label > 65535)
      throw InputError(path, at + "label '" + label_text + "' is not an integer from 1 to 65535 (0 is the background)");
    const bool plain = std::all_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isalnum(c) || c == '_' || c == '-' || c == '.';
    });
    if (!plain || name == "." || name == "..")
      throw InputError(path, at + "object name '" + name + "' may hold only letters, digits, '_', '-' and '.'");
    for (const auto& [other_label, other_name] : objects) {
      if (other_label == label) throw InputError(path, at + "label " + label_text + " is given twice");
      if (other_name == name) throw InputError(path, at + "object '" + name + "' is given twice");
    }
    objects.emplace_back(label, name);
  }
  if (objects.empty()) throw InputError(path, "no object listed (one line per object: '<label> <name>')");
  return objects;
}

/// parseLabelNames of a file.
inline std::vector<std::pair<int, std::string>> readLabelNames(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  return parseLabelNames(in, path);
}

}  // namespace bundletrack::io
