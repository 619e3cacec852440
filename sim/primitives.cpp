// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

namespace {

void require_positive(double value, const char* what) {
  if (!(std::isfinite(value) && value > 0.0))
    throw std::invalid_argument(std::string("primitive: ") + what + " must be positive and finite, got " +
                                std::to_string(value));
}

int add_vertex(TriangleMesh& mesh, double x, double y, double z) {
  mesh.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  return static_cast<int>(mesh.vertices.size()) - 1;
}

// Adds triangle (a, b, c) wound so that its normal points along `outward`.
void add_triangle(TriangleMesh& mesh, int a, int b, int c, const Eigen::Vector3f& outward) {
  const Eigen::Vector3f& pa = mesh.vertices[a];
  const Eigen::Vector3f normal = (mesh.vertices[b] - pa).cross(mesh.vertices[c] - pa);
  if (normal.dot(outward) >= 0.0f)
    mesh.triangles.emplace_back(a, b, c);
  else
    mesh.triangles.emplace_back(a, c, b);
}

// Quad a-b-c-d given around its perimeter.
void add_quad(TriangleMesh& mesh, int a, int b, int c, int d, const Eigen::Vector3f& outward) {
  add_triangle(mesh, a, b, c, outward);
  add_triangle(mesh, a, c, d, outward);
}

TriangleMesh box(const Eigen::Vector3d& size, bool inward) {
  require_positive(size.x(), "box/room size.x");
  require_positive(size.y(), "box/room size.y");
  require_positive(size.z(), "box/room size.z");
  TriangleMesh mesh;
  // Corner i has x = +hx if bit 0, y = +hy if bit 1, z = size.z if bit 2.
  for (int i = 0; i < 8; ++i)
    add_vertex(mesh, (i & 1) ? size.x() / 2 : -size.x() / 2, (i & 2) ? size.y() / 2 : -size.y() / 2,
               (i & 4) ? size.z() : 0.0);
  const float s = inward ? -1.0f : 1.0f;
  add_quad(mesh, 0, 2, 6, 4, s * Eigen::Vector3f(-1, 0, 0));
  add_quad(mesh, 1, 3, 7, 5, s * Eigen::Vector3f(1, 0, 0));
  add_quad(mesh, 0, 1, 5, 4, s * Eigen::Vector3f(0, -1, 0));
  add_quad(mesh, 2, 3, 7, 6, s * Eigen::Vector3f(0, 1, 0));
  add_quad(mesh, 0, 1, 3, 2, s * Eigen::Vector3f(0, 0, -1));
  add_quad(mesh, 4, 5, 7, 6, s * Eigen::Vector3f(0, 0, 1));
  return mesh;
}

TriangleMesh cylinder(double radius, double height, int segments) {
  require_positive(radius, "cylinder radius");
  require_positive(height, "cylinder height");
  TriangleMesh mesh;
  const int bottom_centre = add_vertex(mesh, 0, 0, 0);
  const int top_centre = add_vertex(mesh, 0, 0, height);
  const int first = static_cast<int>(mesh.vertices.size());
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    add_vertex(mesh, radius * std::cos(a), radius * std::sin(a), 0.0);
    add_vertex(mesh, radius * std::cos(a), radius * std::sin(a), height);
  }
  for (int k = 0; k < segments; ++k) {
    const int b0 = first + 2 * k, t0 = b0 + 1;
    const int b1 = first + 2 * ((k + 1) % segments), t1 = b1 + 1;
    const double mid = 2.0 * M_PI * (k + 0.5) / segments;
    add_quad(mesh, b0, b1, t1, t0,
             Eigen::Vector3f(static_cast<float>(std::cos(mid)), static_cast<float>(std::sin(mid)), 0));
    add_triangle(mesh, bottom_centre, b0, b1, Eigen::Vector3f(0, 0, -1));
    add_triangle(mesh, top_centre, t0, t1, Eigen::Vector3f(0, 0, 1));
  }
  return mesh;
}

TriangleMesh sphere(double radius, int segments) {
  require_positive(radius, "sphere radius");
  const int bands = std::max(2, segments / 2);
  TriangleMesh mesh;
  const int south = add_vertex(mesh, 0, 0, -radius);
  const int north = add_vertex(mesh, 0, 0, radius);
  // Ring j (1 .. bands-1) at polar angle pi * j / bands from the north pole.
  auto ring_vertex = [&](int j, int k) { return 2 + (j - 1) * segments + (k % segments); };
  for (int j = 1; j < bands; ++j) {
    const double polar = M_PI * j / bands;
    for (int k = 0; k < segments; ++k) {
      const double a = 2.0 * M_PI * k / segments;
      add_vertex(mesh, radius * std::sin(polar) * std::cos(a), radius * std::sin(polar) * std::sin(a),
                 radius * std::cos(polar));
    }
  }
  auto outward = [&](int a, int b, int c) {
    return Eigen::Vector3f(mesh.vertices[a] + mesh.vertices[b] + mesh.vertices[c]);
  };
  for (int k = 0; k < segments; ++k) {
    const int n0 = ring_vertex(1, k), n1 = ring_vertex(1, k + 1);
    add_triangle(mesh, north, n0, n1, outward(north, n0, n1));
    const int s0 = ring_vertex(bands - 1, k), s1 = ring_vertex(bands - 1, k + 1);
    add_triangle(mesh, south, s0, s1, outward(south, s0, s1));
    for (int j = 1; j + 1 < bands; ++j) {
      const int a = ring_vertex(j, k), b = ring_vertex(j, k + 1);
      const int c = ring_vertex(j + 1, k + 1), d = ring_vertex(j + 1, k);
      add_quad(mesh, a, b, c, d, outward(a, b, c));
    }
  }
  return mesh;
}

TriangleMesh plane(const Eigen::Vector3d& size) {
  require_positive(size.x(), "plane size.x");
  require_positive(size.y(), "plane size.y");
  TriangleMesh mesh;
  const double hx = size.x() / 2, hy = size.y() / 2;
  const int a = add_vertex(mesh, -hx, -hy, 0), b = add_vertex(mesh, hx, -hy, 0);
  const int c = add_vertex(mesh, hx, hy, 0), d = add_vertex(mesh, -hx, hy, 0);
  add_quad(mesh, a, b, c, d, Eigen::Vector3f(0, 0, 1));
  return mesh;
}

}  // namespace

TriangleMesh triangulate(const PrimitiveSpec& shape) {
  using Kind = PrimitiveSpec::Kind;
  if ((shape.kind == Kind::Cylinder || shape.kind == Kind::Sphere) && shape.segments < 3)
    throw std::invalid_argument("primitive: segments must be at least 3, got " +
                                std::to_string(shape.segments));
  switch (shape.kind) {
    case Kind::Room: return box(shape.size, true);
    case Kind::Box: return box(shape.size, false);
    case Kind::Cylinder: return cylinder(shape.radius, shape.height, shape.segments);
    case Kind::Sphere: return sphere(shape.radius, shape.segments);
    case Kind::Plane: return plane(shape.size);
    case Kind::Mesh: break;
  }
  throw std::invalid_argument("primitive: a mesh shape ('" + shape.mesh_path +
                              "') cannot be triangulated; its mesh must be loaded from the file");
}

void validate(const TriangleMesh& mesh) {
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite())
      throw std::invalid_argument("mesh: vertex " + std::to_string(i) + " is not finite (NaN or inf)");
  const int n = static_cast<int>(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const int index = mesh.triangles[i][c];
      if (index < 0 || index >= n)
        throw std::invalid_argument("mesh: triangle " + std::to_string(i) + " has vertex index " +
                                    std::to_string(index) + " out of range [0, " + std::to_string(n) +
                                    ")");
    }
}

TriangleMesh mesh_of(const PrimitiveSpec& shape, const TriangleMesh& mesh) {
  if (!mesh.triangles.empty() || shape.kind == PrimitiveSpec::Kind::Mesh) return mesh;
  return triangulate(shape);
}

}  // namespace sonomap::sim
