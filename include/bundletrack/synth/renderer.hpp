#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "bundletrack/core/camera.hpp"
#include "bundletrack/core/se3.hpp"
#include "bundletrack/synth/mesh.hpp"
#include "bundletrack/synth/texture.hpp"

namespace bundletrack::synth {

/// An infinite textured plane through `origin` spanned by the unit vectors u_axis, v_axis; the
/// texture repeats every `tile` metres. Coordinates in the camera frame at render time.
struct TexturedPlane {
  Eigen::Vector3d origin, u_axis, v_axis;
  double tile = 1.0;
  const cv::Mat* texture = nullptr;
  int label = 0;
};

/// A mesh placed in the camera frame.
struct MeshInstance {
  const TriangleMesh* mesh = nullptr;
  const cv::Mat* texture = nullptr;
  SE3d T_cam_mesh;
  int label = 0;
};

/// What each pixel sees. depth is the z coordinate in metres (0 where nothing is hit), label the
/// label of the visible surface (-1 where nothing is hit), color linear BGR in [0, 255], normal the
/// camera-frame unit normal facing the camera.
struct RenderBuffers {
  cv::Mat depth;  // CV_32FC1
  cv::Mat label;  // CV_32SC1
  cv::Mat color;  // CV_32FC3
  cv::Mat normal;  // CV_32FC3
};

/// Lambertian shading with an ambient term; the light shines along `light` (camera frame).
struct Lighting {
  Eigen::Vector3d light = Eigen::Vector3d(0.4, 0.6, 1.0).normalized();
  double ambient = 0.35;
  double shade(const Eigen::Vector3d& n) const { return ambient + (1.0 - ambient) * std::max(0.0, -n.dot(light)); }
};

/// Z-buffer renderer: planes are ray cast per pixel (their depth is exact), meshes are rasterised
/// with perspective-correct interpolation (1/z is affine in the image for a planar triangle, so
/// triangle depth is exact too). Pixel centres sit at integer (u, v).
class Renderer {
 public:
  Renderer(const PinholeCamerad& camera, cv::Size size, double near = 0.02) : camera_(camera), size_(size), near_(near) {}

  RenderBuffers render(const std::vector<TexturedPlane>& planes, const std::vector<MeshInstance>& meshes,
                       const Lighting& lighting = {}) const {
    RenderBuffers out{cv::Mat(size_, CV_32FC1, cv::Scalar(0)), cv::Mat(size_, CV_32SC1, cv::Scalar(-1)),
                      cv::Mat(size_, CV_32FC3, cv::Scalar::all(0)), cv::Mat(size_, CV_32FC3, cv::Scalar::all(0))};
    cv::Mat zbuffer(size_, CV_64FC1, cv::Scalar(std::numeric_limits<double>::infinity()));
    for (const auto& plane : planes) castPlane(plane, lighting, zbuffer, out);
    for (const auto& instance : meshes) rasterise(instance, lighting, zbuffer, out);
    return out;
  }

 private:
  void write(RenderBuffers& out, cv::Mat& zbuffer, int v, int u, double z, int label, const cv::Vec3f& color,
             Eigen::Vector3d n, const Eigen::Vector3d& p) const {
    if (n.dot(p) > 0.0) n = -n;
    zbuffer.at<double>(v, u) = z;
    out.depth.at<float>(v, u) = float(z);
    out.label.at<int>(v, u) = label;
    out.color.at<cv::Vec3f>(v, u) = color;
    out.normal.at<cv::Vec3f>(v, u) = cv::Vec3f(float(n.x()), float(n.y()), float(n.z()));
  }

  void castPlane(const TexturedPlane& plane, const Lighting& lighting, cv::Mat& zbuffer, RenderBuffers& out) const {
    const Eigen::Vector3d n = plane.u_axis.cross(plane.v_axis).normalized();
    for (int v = 0; v < size_.height; ++v) {
      for (int u = 0; u < size_.width; ++u) {
        const Eigen::Vector3d ray = camera_.unproject(u, v, 1.0);  // z = 1, so depth = t
        const double denom = n.dot(ray);
        if (std::abs(denom) < 1e-12) continue;
        const double z = n.dot(plane.origin) / denom;
        if (z <= near_ || z >= zbuffer.at<double>(v, u)) continue;
        const Eigen::Vector3d p = z * ray, local = p - plane.origin;
        const cv::Vec3f albedo =
            sampleTexture(*plane.texture, local.dot(plane.u_axis) / plane.tile, local.dot(plane.v_axis) / plane.tile);
        const Eigen::Vector3d facing = n.dot(p) > 0.0 ? Eigen::Vector3d(-n) : n;
        write(out, zbuffer, v, u, z, plane.label, albedo * float(lighting.shade(facing)), n, p);
      }
    }
  }

  void rasterise(const MeshInstance& instance, const Lighting& lighting, cv::Mat& zbuffer, RenderBuffers& out) const {
    const TriangleMesh& mesh = *instance.mesh;
    const Eigen::Matrix3d R = instance.T_cam_mesh.rotationMatrix();
    std::vector<Eigen::Vector3d> p(mesh.positions.size()), n(mesh.normals.size());
    std::vector<Eigen::Vector2d> uv(mesh.positions.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      p[i] = instance.T_cam_mesh * mesh.positions[i];
      n[i] = R * mesh.normals[i];
      uv[i] = camera_.project(p[i]);
    }
    for (const auto& [a, b, c] : mesh.triangles) {
      if (p[a].z() <= near_ || p[b].z() <= near_ || p[c].z() <= near_) continue;  // no near-plane clipping
      const double area = (uv[b] - uv[a]).x() * (uv[c] - uv[a]).y() - (uv[c] - uv[a]).x() * (uv[b] - uv[a]).y();
      if (std::abs(area) < 1e-12) continue;
      const int u0 = std::max(0, int(std::ceil(std::min({uv[a].x(), uv[b].x(), uv[c].x()}))));
      const int u1 = std::min(size_.width - 1, int(std::floor(std::max({uv[a].x(), uv[b].x(), uv[c].x()}))));
      const int v0 = std::max(0, int(std::ceil(std::min({uv[a].y(), uv[b].y(), uv[c].y()}))));
      const int v1 = std::min(size_.height - 1, int(std::floor(std::max({uv[a].y(), uv[b].y(), uv[c].y()}))));
      const auto edge = [](const Eigen::Vector2d& s, const Eigen::Vector2d& e, double x, double y) {
        return (e.x() - s.x()) * (y - s.y()) - (e.y() - s.y()) * (x - s.x());
      };
      for (int v = v0; v <= v1; ++v) {
        for (int u = u0; u <= u1; ++u) {
          // Barycentric weights; dividing by the signed area accepts either winding.
          const double ba = edge(uv[b], uv[c], u, v) / area, bb = edge(uv[c], uv[a], u, v) / area;
          const double bc = 1.0 - ba - bb;
          if (ba < 0.0 || bb < 0.0 || bc < 0.0) continue;
          const double qa = ba / p[a].z(), qb = bb / p[b].z(), qc = bc / p[c].z();
          const double z = 1.0 / (qa + qb + qc);
          if (z >= zbuffer.at<double>(v, u)) continue;
          const Eigen::Vector2d t = z * (qa * mesh.uvs[a] + qb * mesh.uvs[b] + qc * mesh.uvs[c]);
          const Eigen::Vector3d normal = (qa * n[a] + qb * n[b] + qc * n[c]).normalized();
          const Eigen::Vector3d point = camera_.unproject(u, v, z);
          const Eigen::Vector3d facing = normal.dot(point) > 0.0 ? Eigen::Vector3d(-normal) : normal;
          const cv::Vec3f albedo = sampleTexture(*instance.texture, t.x(), t.y());
          write(out, zbuffer, v, u, z, instance.label, albedo * float(lighting.shade(facing)), normal, point);
        }
      }
    }
  }

  PinholeCamerad camera_;
  cv::Size size_;
  double near_;
};

}  // namespace bundletrack::synth
