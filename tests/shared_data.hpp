#pragma once

#include <cstdlib>
#include <filesystem>

// The real sequences of ../shared/data, or the folder named by $BUNDLETRACK_DATA. Tests that use
// them skip when the folder is absent.
inline std::filesystem::path sharedDataDir() {
  if (const char* dir = std::getenv("BUNDLETRACK_DATA")) return dir;
  return BUNDLETRACK_SHARED_DATA;
}
