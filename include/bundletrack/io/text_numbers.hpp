#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bundletrack/core/error.hpp"
#include "bundletrack/io/file_access.hpp"

namespace bundletrack::io {

/// All whitespace-separated numbers of a text; a token that is not a number is an error naming
/// `path`, the text's source.
inline std::vector<double> parseNumbers(std::istream& in, const std::filesystem::path& path) {
  std::vector<double> values;
  std::string token;
  while (in >> token) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size()) throw InputError(path, "'" + token + "' is not a number");
    values.push_back(value);
  }
  return values;
}

/// All whitespace-separated numbers of a text file (parseNumbers).
inline std::vector<double> readNumbers(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  return parseNumbers(in, path);
}

}  // namespace bundletrack::io
