// libFuzzer target: the sequence reader's parsers on arbitrary bytes. The first byte picks what
// the rest is read as (cam_K.txt, a pose file, model/points.xyz, a colour, depth or mask image,
// labels/objects.txt, a label image);
// an InputError is the expected answer to bad input, anything else escaping -- another exception,
// a crash, a sanitizer report -- is a bug.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "bundletrack/io/image_files.hpp"
#include "bundletrack/io/intrinsics_file.hpp"
#include "bundletrack/io/label_images.hpp"
#include "bundletrack/io/point_files.hpp"
#include "bundletrack/io/pose_files.hpp"

namespace bt = bundletrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::filesystem::path source = "fuzz-input";
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  const std::vector<uchar> bytes(data + 1, data + size);
  std::istringstream in(text);
  try {
    switch (data[0] % 8) {  // '0' .. '7' in the seed files
      case 0: bt::io::intrinsicsFromNumbers(bt::io::parseNumbers(in, source), source); break;
      case 1: bt::io::poseFromNumbers(bt::io::parseNumbers(in, source), source); break;
      case 2: bt::io::parsePoints(in, source); break;
      case 3: bt::io::decodeImage(bytes, cv::IMREAD_COLOR, source); break;
      case 4: bt::io::depthFromImage(bt::io::decodeImage(bytes, cv::IMREAD_UNCHANGED, source), 0.001, source); break;
      case 5: bt::io::maskFromImage(bt::io::decodeImage(bytes, cv::IMREAD_UNCHANGED, source)); break;
      case 6: bt::io::parseLabelNames(in, source); break;
      default: bt::io::labelMask(bt::io::labelsFromImage(bt::io::decodeImage(bytes, cv::IMREAD_UNCHANGED, source), source), 1); break;
    }
  } catch (const bt::InputError&) {
  }
  return 0;
}
