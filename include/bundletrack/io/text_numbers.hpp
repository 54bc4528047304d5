#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bundletrack/core/error.hpp"

namespace bundletrack::io {

/// All whitespace-separated numbers of a text file; a token that is not a number is an error.
inline std::vector<double> readNumbers(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, std::filesystem::exists(path) ? "cannot open file" : "file not found");
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

}  // namespace bundletrack::io
