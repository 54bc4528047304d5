#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <Eigen/Core>

#include "bundletrack/core/error.hpp"
#include "bundletrack/io/file_access.hpp"

namespace bundletrack::io {

/// The points of an .xyz text: one point per line, "x y z" in metres; further columns (normals,
/// colour) are ignored, blank lines skipped.
inline std::vector<Eigen::Vector3f> parsePoints(std::istream& in, const std::filesystem::path& path) {
  std::vector<Eigen::Vector3f> points;
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    double x, y, z;
    if (!(fields >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
      throw InputError(path, "line " + std::to_string(line_number) + " does not start with three finite numbers");
    points.emplace_back(float(x), float(y), float(z));
  }
  if (points.empty()) throw InputError(path, "no points");
  return points;
}

/// Reads an .xyz file (parsePoints).
inline std::vector<Eigen::Vector3f> readPoints(const std::filesystem::path& path) {
  std::ifstream in = openForReading(path);
  return parsePoints(in, path);
}

inline void writePoints(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& points) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot write file");
  for (const auto& p : points) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  if (!out) throw InputError(path, "write failed");
}

}  // namespace bundletrack::io
