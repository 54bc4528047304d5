#pragma once

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "bundletrack/core/error.hpp"

namespace bundletrack::io {

/// Opens a file to read, or says what is wrong with it: not there, a directory, a broken link or
/// a link loop, no permission to read it.
inline std::ifstream openForReading(const std::filesystem::path& path, std::ios::openmode mode = std::ios::in) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) throw InputError(path, "file not found");
  if (error) throw InputError(path, "cannot be reached: " + error.message());
  if (std::filesystem::is_directory(status)) throw InputError(path, "is a directory, expected a file");
  std::ifstream in(path, mode);
  if (!in) throw InputError(path, std::string("cannot be read: ") + std::strerror(errno));
  return in;
}

}  // namespace bundletrack::io
