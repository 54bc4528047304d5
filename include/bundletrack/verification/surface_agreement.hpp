#pragma once

#include <vector>

#include "bundletrack/core/surface_gate.hpp"
#include "bundletrack/verification/pose_verifier.hpp"

namespace bundletrack {

struct SurfaceAgreementSettings {
  /// A pose is kept when this fraction of the frame's points that land on another node's surface
  /// lies on it. Sensor noise is a few mm at the working range, so a right pose puts nearly every
  /// overlapping point within 1 cm.
  double min_agreement = 0.5;
  /// Right poses reach 0.9-1.0 agreement (5th percentile 0.72-0.97 over the synthetic and shared
  /// sequences); a pose with nothing but the surface behind it (Evidence::SurfaceOnly) has no
  /// inlier count either, so it must do better than min_agreement.
  double recovery_min_agreement = 0.8;
  /// On the surface: within 1 cm and 45 degrees.
  SurfaceGate gate{0.01f, 45.0f};
};

/// Verification by surface agreement: of the current frame's grid points that land on a valid
/// point of another node (projective association under the optimised poses), the fraction that
/// passes the gate, widened for the two grids' noise (NoiseScale::between). Grids have holes
/// (depth dropouts, undefined normals), so points landing in a hole say nothing, nor do points
/// whose normal faces away from that node's camera behind its reading there (a face it could not
/// have seen, which the widened gate of far readings would otherwise set against the face it did
/// see); when fewer than a quarter of the points land anywhere the agreement is 0.
class SurfaceAgreement {
 public:
  using Settings = SurfaceAgreementSettings;

  explicit SurfaceAgreement(Settings settings = {}) : settings_(settings) {}

  bool accepts(const PoseGraph& graph, Evidence evidence) const {
    return agreement(graph) >=
           (evidence == Evidence::SurfaceOnly ? settings_.recovery_min_agreement : settings_.min_agreement);
  }

  double agreement(const PoseGraph& graph) const {
    const SurfaceGrid& current = graph.nodes.back()->surface;
    std::vector<SE3d> T_k_c;
    std::vector<SurfaceGate::Bounds<double>> bounds;  // per node: the gate widened for the pair's noise
    for (std::size_t k = 0; k + 1 < graph.nodes.size(); ++k) {
      T_k_c.push_back(graph.poses[k] * graph.poses.back().inverse());
      const double scale = NoiseScale::between(current.noise_scale, graph.nodes[k]->surface.noise_scale);
      bounds.push_back(settings_.gate.widened(scale).bounds<double>());
    }
    int valid = 0, compared = 0, agreeing = 0;
    for (const cv::Point& cell : current.cells) {
      const cv::Vec3f& pc = current.point(cell);
      if (pc[2] <= 0.0f) continue;
      ++valid;
      const Eigen::Vector3d p(pc[0], pc[1], pc[2]);
      const cv::Vec3f& nc = current.normal(cell);
      bool landed = false, agrees = false;
      for (std::size_t k = 0; k < T_k_c.size() && !agrees; ++k) {
        const SurfaceGrid& other = graph.nodes[k]->surface;
        const Eigen::Vector3d q = T_k_c[k] * p;
        int u = 0, v = 0;
        if (!other.camera.pixelOf(q, u, v) || !other.inside(u, v)) continue;
        const cv::Vec3f& pk = other.point(u, v);
        if (pk[2] <= 0.0f) continue;
        // A face turned away from k's camera and behind k's reading: k saw the object's front
        // there, it cannot have seen this point. (In front of the reading it contradicts k.)
        const Eigen::Vector3d n = T_k_c[k].rotation() * Eigen::Vector3d(nc[0], nc[1], nc[2]);
        if (n.dot(q) > 0.0 && q.z() >= double(pk[2])) continue;
        landed = true;
        if ((Eigen::Vector3d(pk[0], pk[1], pk[2]) - q).squaredNorm() > bounds[k].max_squared_distance) continue;
        const cv::Vec3f& nk = other.normal(u, v);
        agrees = n.dot(Eigen::Vector3d(nk[0], nk[1], nk[2])) >= bounds[k].cos_max_angle;
      }
      compared += landed;
      agreeing += agrees;
    }
    if (compared == 0 || 4 * compared < valid) return 0.0;
    return double(agreeing) / double(compared);
  }

 private:
  Settings settings_;
};

}  // namespace bundletrack
