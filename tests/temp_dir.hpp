#pragma once

#include <filesystem>
#include <random>
#include <string>

// A fresh directory under the system temp folder, removed with the object.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    std::random_device seed;
    path_ = std::filesystem::temp_directory_path() / ("bundletrack_" + tag + "_" + std::to_string(seed()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};
