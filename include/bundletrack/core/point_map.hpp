#pragma once

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/depth_noise.hpp"

namespace bundletrack {

/// Organised point cloud: the camera-frame point of every pixel (CV_32FC3), zero where depth is 0.
inline cv::Mat unprojectDepth(const cv::Mat& depth, const PinholeCameraf& camera) {
  CV_Assert(depth.type() == CV_32FC1);
  cv::Mat points(depth.size(), CV_32FC3);
  points.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int* pos) {
    const float z = depth.at<float>(pos[0], pos[1]);
    if (z <= 0.0f) {
      p = cv::Vec3f(0.0f, 0.0f, 0.0f);
      return;
    }
    const auto q = camera.unproject(float(pos[1]), float(pos[0]), z);
    p = cv::Vec3f(q.x(), q.y(), q.z());
  });
  return points;
}

/// Unit normals from the cross product of central differences of the point map, facing the
/// camera (n . p < 0). A normal is undefined (zero) where a neighbour is invalid or lies more than
/// max_depth_jump (metres, widened by `noise` at the centre's depth) from the centre in depth, i.e.
/// across a depth discontinuity.
inline cv::Mat estimateNormals(const cv::Mat& points, float max_depth_jump = 0.02f, const NoiseScale& noise = NoiseScale()) {
  CV_Assert(points.type() == CV_32FC3);
  cv::Mat normals(points.size(), CV_32FC3, cv::Scalar::all(0));
  normals.forEach<cv::Vec3f>([&](cv::Vec3f& n, const int* pos) {
    const int v = pos[0], u = pos[1];
    if (v == 0 || u == 0 || v + 1 == points.rows || u + 1 == points.cols) return;
    const cv::Vec3f& c = points.at<cv::Vec3f>(v, u);
    const cv::Vec3f& left = points.at<cv::Vec3f>(v, u - 1);
    const cv::Vec3f& right = points.at<cv::Vec3f>(v, u + 1);
    const cv::Vec3f& up = points.at<cv::Vec3f>(v - 1, u);
    const cv::Vec3f& down = points.at<cv::Vec3f>(v + 1, u);
    const float jump = noise.widen(max_depth_jump, c[2]);
    for (const cv::Vec3f* q : {&c, &left, &right, &up, &down})
      if ((*q)[2] <= 0.0f || std::abs((*q)[2] - c[2]) > jump) return;
    cv::Vec3f cross = (right - left).cross(down - up);
    const float length = float(cv::norm(cross));
    if (length <= 0.0f) return;
    cross /= length;
    n = cross.dot(c) > 0.0f ? -cross : cross;
  });
  return normals;
}

}  // namespace bundletrack
