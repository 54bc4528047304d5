#pragma once

#include <filesystem>
#include <fstream>
#include <vector>

#include "bundletrack/core/error.hpp"
#include "bundletrack/graph/object_model.hpp"

namespace bundletrack::io {

/// Writes an object model as an ASCII PLY point cloud: x y z (metres), nx ny nz, red green blue.
inline void writeModelPly(const std::filesystem::path& path, const std::vector<ModelPoint>& model) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot write file");
  out << "ply\nformat ascii 1.0\ncomment bundletrack: object model fused from the keyframes, object frame\n"
      << "element vertex " << model.size() << '\n'
      << "property float x\nproperty float y\nproperty float z\n"
      << "property float nx\nproperty float ny\nproperty float nz\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  for (const ModelPoint& p : model)
    out << p.position.x() << ' ' << p.position.y() << ' ' << p.position.z() << ' ' << p.normal.x() << ' '
        << p.normal.y() << ' ' << p.normal.z() << ' ' << int(p.color[2]) << ' ' << int(p.color[1]) << ' '
        << int(p.color[0]) << '\n';
  if (!out) throw InputError(path, "write failed");
}

}  // namespace bundletrack::io
