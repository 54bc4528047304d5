#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>

#include "bundletrack/core/se3.hpp"
#include "bundletrack/io/text_numbers.hpp"

namespace bundletrack::io {

/// A 4x4 homogeneous transform from its 16 numbers, row by row. The rotation block must be
/// orthonormal with determinant +1 to 1e-3 (annotation files are printed with a few digits).
inline SE3d poseFromNumbers(const std::vector<double>& v, const std::filesystem::path& path) {
  if (v.size() != 16) throw InputError(path, "expected 16 numbers (4x4 pose), found " + std::to_string(v.size()));
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T(v.data());
  if (!T.allFinite()) throw InputError(path, "pose has a non-finite entry");
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-6)
    throw InputError(path, "last row of the pose must be 0 0 0 1");
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 || R.determinant() < 0.0)
    throw InputError(path, "rotation block is not a rotation matrix");
  return SE3d::fromMatrix(T);
}

/// Reads a pose file (poseFromNumbers).
inline SE3d readPose(const std::filesystem::path& path) { return poseFromNumbers(readNumbers(path), path); }

inline void writePose(const std::filesystem::path& path, const SE3d& pose) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot write file");
  const Eigen::Matrix4d T = pose.matrix();
  out << std::setprecision(10) << std::fixed;
  for (int r = 0; r < 4; ++r) out << T(r, 0) << ' ' << T(r, 1) << ' ' << T(r, 2) << ' ' << T(r, 3) << '\n';
  if (!out) throw InputError(path, "write failed");
}

}  // namespace bundletrack::io
