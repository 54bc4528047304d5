#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Core>

namespace bundletrack::synth {

/// A textured triangle mesh in its own (object) frame: per-vertex position, unit normal and
/// texture coordinate in [0, 1]^2; triangles index vertices.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3d> normals;
  std::vector<Eigen::Vector2d> uvs;
  std::vector<std::array<int, 3>> triangles;

  int addVertex(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector2d& uv) {
    positions.push_back(p);
    normals.push_back(n.normalized());
    uvs.push_back(uv);
    return int(positions.size()) - 1;
  }

  /// Two triangles over the quad a-b-c-d (in order around its boundary).
  void addQuad(int a, int b, int c, int d) {
    triangles.push_back({a, b, c});
    triangles.push_back({a, c, d});
  }

  double triangleArea(std::size_t t) const {
    const auto& [a, b, c] = triangles[t];
    return 0.5 * (positions[b] - positions[a]).cross(positions[c] - positions[a]).norm();
  }

  /// Area-weighted uniform samples on the surface (the object model for ADD/ADD-S).
  std::vector<Eigen::Vector3f> sampleSurface(std::size_t count, unsigned seed) const {
    std::vector<double> cumulative(triangles.size());
    double total = 0.0;
    for (std::size_t t = 0; t < triangles.size(); ++t) cumulative[t] = total += triangleArea(t);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<Eigen::Vector3f> samples;
    samples.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
      const auto t = std::size_t(std::lower_bound(cumulative.begin(), cumulative.end(), uniform(rng) * total) -
                                 cumulative.begin());
      double s = uniform(rng), r = uniform(rng);
      if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
      const auto& [a, b, c] = triangles[std::min(t, triangles.size() - 1)];
      samples.push_back((positions[a] + s * (positions[b] - positions[a]) + r * (positions[c] - positions[a])).cast<float>());
    }
    return samples;
  }
};

/// Box centred at the origin with edge lengths `size`. Each face maps to one cell of a 3x2 texture
/// atlas, so every face shows a different part of the texture.
inline TriangleMesh makeBox(const Eigen::Vector3d& size) {
  TriangleMesh mesh;
  const Eigen::Vector3d h = 0.5 * size;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const double sign = face % 2 == 0 ? 1.0 : -1.0;
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n[axis] = sign;
    Eigen::Vector3d e1 = Eigen::Vector3d::Zero(), e2 = Eigen::Vector3d::Zero();
    e1[(axis + 1) % 3] = h[(axis + 1) % 3];
    e2[(axis + 2) % 3] = h[(axis + 2) % 3];
    const Eigen::Vector3d centre = sign * h[axis] * Eigen::Vector3d::Unit(axis);
    const Eigen::Vector2d cell(double(face % 3) / 3.0, double(face / 3) / 2.0);
    int corner[4];
    const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; ++k)
      corner[k] = mesh.addVertex(centre + su[k] * e1 + sv[k] * e2, n,
                                 cell + Eigen::Vector2d((su[k] + 1.0) / 6.0, (sv[k] + 1.0) / 4.0));
    mesh.addQuad(corner[0], corner[1], corner[2], corner[3]);
  }
  return mesh;
}

namespace detail {

/// Open cylinder wall of `radius` between heights z0 and z1 around the z axis; normals point out
/// (or in, for inward = true). The texture wraps once around: u = angle / 2 pi, v from v0 to v1.
inline void addCylinderWall(TriangleMesh& mesh, double radius, double z0, double z1, int segments, bool inward,
                            double v0, double v1) {
  const int first = int(mesh.positions.size());
  for (int i = 0; i <= segments; ++i) {
    const double a = 2.0 * std::numbers::pi * i / segments;
    const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0.0);
    const Eigen::Vector3d n = inward ? -radial : radial;
    mesh.addVertex(radius * radial + z0 * Eigen::Vector3d::UnitZ(), n, {double(i) / segments, v0});
    mesh.addVertex(radius * radial + z1 * Eigen::Vector3d::UnitZ(), n, {double(i) / segments, v1});
  }
  for (int i = 0; i < segments; ++i) {
    const int a = first + 2 * i;
    mesh.addQuad(a, a + 2, a + 3, a + 1);
  }
}

/// Annulus (or disc when inner = 0) at height z with normal +z or -z; texture is a planar map
/// into the uv square [u0, u0 + 0.25] x [v0, v0 + 0.25].
inline void addRing(TriangleMesh& mesh, double inner, double outer, double z, bool up, int segments, double u0,
                    double v0) {
  const Eigen::Vector3d n(0.0, 0.0, up ? 1.0 : -1.0);
  const auto uv = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(u0 + 0.125 * (1.0 + p.x() / outer), v0 + 0.125 * (1.0 + p.y() / outer));
  };
  const int first = int(mesh.positions.size());
  for (int i = 0; i <= segments; ++i) {
    const double a = 2.0 * std::numbers::pi * i / segments;
    const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0.0);
    const Eigen::Vector3d p_in = inner * radial + z * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d p_out = outer * radial + z * Eigen::Vector3d::UnitZ();
    mesh.addVertex(p_in, n, uv(p_in));
    mesh.addVertex(p_out, n, uv(p_out));
  }
  for (int i = 0; i < segments; ++i) {
    const int a = first + 2 * i;
    mesh.addQuad(a, a + 1, a + 3, a + 2);
  }
}

}  // namespace detail

/// Closed cylinder (a can) around the z axis, base at z = -height/2.
inline TriangleMesh makeCylinder(double radius, double height, int segments = 64) {
  TriangleMesh mesh;
  detail::addCylinderWall(mesh, radius, -0.5 * height, 0.5 * height, segments, false, 0.0, 0.75);
  detail::addRing(mesh, 0.0, radius, 0.5 * height, true, segments, 0.0, 0.75);
  detail::addRing(mesh, 0.0, radius, -0.5 * height, false, segments, 0.25, 0.75);
  return mesh;
}

/// A mug: cylindrical shell (outer radius, wall thickness, open top, solid bottom) around the z axis
/// with a half-torus handle on the +x side. Non-convex: the inside and the handle's hole
/// self-occlude.
inline TriangleMesh makeMug(double radius, double height, double wall, int segments = 64) {
  TriangleMesh mesh;
  const double z0 = -0.5 * height, z1 = 0.5 * height;
  detail::addCylinderWall(mesh, radius, z0, z1, segments, false, 0.0, 0.7);
  detail::addCylinderWall(mesh, radius - wall, z0 + wall, z1, segments, true, 0.7, 0.75);
  detail::addRing(mesh, radius - wall, radius, z1, true, segments, 0.5, 0.75);
  detail::addRing(mesh, 0.0, radius - wall, z0 + wall, true, segments, 0.25, 0.75);
  detail::addRing(mesh, 0.0, radius, z0, false, segments, 0.0, 0.75);
  // Handle: tube of radius `tube` along a half circle of radius `arc` in the xz plane, centred on
  // the outer wall so that both ends enter the wall.
  const double arc = 0.3 * height, tube = 0.25 * wall + 0.004;
  const int arc_steps = 24, ring_steps = 12;
  const int first = int(mesh.positions.size());
  for (int i = 0; i <= arc_steps; ++i) {
    const double a = -0.5 * std::numbers::pi + std::numbers::pi * i / arc_steps;
    const Eigen::Vector3d centre(radius - 0.5 * wall + arc * std::cos(a), 0.0, arc * std::sin(a));
    const Eigen::Vector3d out(std::cos(a), 0.0, std::sin(a));
    for (int j = 0; j <= ring_steps; ++j) {
      const double b = 2.0 * std::numbers::pi * j / ring_steps;
      const Eigen::Vector3d n = std::cos(b) * out + std::sin(b) * Eigen::Vector3d::UnitY();
      mesh.addVertex(centre + tube * n, n, {0.75 + 0.25 * double(i) / arc_steps, 0.75 + 0.25 * double(j) / ring_steps});
    }
  }
  for (int i = 0; i < arc_steps; ++i) {
    for (int j = 0; j < ring_steps; ++j) {
      const int a = first + i * (ring_steps + 1) + j;
      mesh.addQuad(a, a + ring_steps + 1, a + ring_steps + 2, a + 1);
    }
  }
  return mesh;
}

/// A chair, the large weakly structured object of the stress matrix: four legs, a seat and a
/// back (boxes; 0.36 x 0.36 m footprint, seat at 0.33-0.36 m, back up to 0.66 m, diagonal 0.83 m),
/// centred on its bounding box, z up, the back on the -y side.
inline TriangleMesh makeChair() {
  const double width = 0.36, leg = 0.03, leg_height = 0.33, seat = 0.03, back = 0.30, top = leg_height + seat + back;
  const auto part = [&](const Eigen::Vector3d& size, const Eigen::Vector3d& centre) {
    TriangleMesh box = makeBox(size);
    for (auto& p : box.positions) p += centre - Eigen::Vector3d(0.0, 0.0, 0.5 * top);
    return box;
  };
  TriangleMesh chair;
  const auto append = [&](const TriangleMesh& box) {
    const int first = int(chair.positions.size());
    for (std::size_t k = 0; k < box.positions.size(); ++k) chair.addVertex(box.positions[k], box.normals[k], box.uvs[k]);
    for (const auto& t : box.triangles) chair.triangles.push_back({first + t[0], first + t[1], first + t[2]});
  };
  const double corner = 0.5 * (width - leg);
  for (const double x : {-corner, corner})
    for (const double y : {-corner, corner}) append(part({leg, leg, leg_height}, {x, y, 0.5 * leg_height}));
  append(part({width, width, seat}, {0.0, 0.0, leg_height + 0.5 * seat}));
  append(part({width, leg, back}, {0.0, -corner, leg_height + seat + 0.5 * back}));
  return chair;
}

}  // namespace bundletrack::synth
