#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace bundletrack {

/// Bad input (a file, an image, a setting): the message names the source and the problem, e.g.
/// "seq/depth/000003.png: depth must be a single-channel 16-bit image, got 8-bit with 3 channels".
class InputError : public std::runtime_error {
 public:
  InputError(const std::filesystem::path& source, const std::string& problem)
      : std::runtime_error(source.string() + ": " + problem), source_(source), problem_(problem) {}

  const std::filesystem::path& source() const { return source_; }
  const std::string& problem() const { return problem_; }

 private:
  std::filesystem::path source_;
  std::string problem_;
};

}  // namespace bundletrack
