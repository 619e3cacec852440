// SPDX-License-Identifier: GPL-3.0-or-later
// Surface samples of a mesh (core/marching_cubes.hpp): dense enough for the rasters, and no
// point twice, since every sample costs the rasters work on every frame.
#include "core/marching_cubes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace sonomap;

TEST_CASE("a flat patch of 4 x 4 squares of 5 cm sampled 2.5 cm apart is the 13 x 13 lattice of "
          "5/3 cm steps, each point once",
          "[surface][samples]") {
  // Each square is two triangles with the diagonal from (0, 0) to (1, 1). Their longest edge,
  // the 7.1 cm diagonal, needs n = 3 divisions, so every sub-triangle's corners lie on the
  // lattice of a third of a square; the squares share their edges and corners.
  constexpr int kSquares = 4;
  constexpr float kSide = 0.05f;
  SurfaceMesh mesh;
  auto vertex_index = [](int i, int j) { return i * (kSquares + 1) + j; };
  for (int i = 0; i <= kSquares; ++i)
    for (int j = 0; j <= kSquares; ++j) mesh.vertices.emplace_back(i * kSide, j * kSide, 1.0f);
  for (int i = 0; i < kSquares; ++i)
    for (int j = 0; j < kSquares; ++j) {
      const int v00 = vertex_index(i, j), v10 = vertex_index(i + 1, j);
      const int v11 = vertex_index(i + 1, j + 1), v01 = vertex_index(i, j + 1);
      mesh.triangles.emplace_back(v00, v10, v11);
      mesh.triangles.emplace_back(v00, v11, v01);
    }
  std::vector<Eigen::Vector3f> samples;
  sample_surface(mesh, 0.025, samples);

  constexpr int kSteps = 3 * kSquares;  // lattice steps per side
  CHECK(samples.size() == (kSteps + 1) * (kSteps + 1));
  std::vector<int> hits((kSteps + 1) * (kSteps + 1), 0);
  for (const Eigen::Vector3f& p : samples) {
    const double step = kSide / 3.0;
    const long i = std::lround(p.x() / step), j = std::lround(p.y() / step);
    INFO("sample " << p.transpose());
    REQUIRE(i >= 0);
    REQUIRE(i <= kSteps);
    REQUIRE(j >= 0);
    REQUIRE(j <= kSteps);
    CHECK(std::abs(p.x() - i * step) < 1e-6);  // on the lattice
    CHECK(std::abs(p.y() - j * step) < 1e-6);
    CHECK(p.z() == 1.0f);
    ++hits[i * (kSteps + 1) + j];
  }
  CHECK(std::count(hits.begin(), hits.end(), 1) == static_cast<long>(hits.size()));  // each once
}

TEST_CASE("an edge that its two triangles divide differently keeps both divisions", "[surface][samples]") {
  // A small triangle (longest edge 2.8 cm: n = 2) beside a long one (7.2 cm: n = 3) on their
  // shared 2.8 cm edge: the small one halves it, the long one divides it in thirds. Both
  // divisions must be there, or the long triangle's rows of samples would end in a gap.
  SurfaceMesh mesh;
  mesh.vertices = {{0, 0, 0}, {0.02f, 0, 0}, {0, 0.02f, 0}, {0.06f, 0.06f, 0}};
  mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
  std::vector<Eigen::Vector3f> samples;
  sample_surface(mesh, 0.025, samples);
  auto has = [&](const Eigen::Vector3f& q) {
    return std::any_of(samples.begin(), samples.end(), [&](const Eigen::Vector3f& p) { return (p - q).norm() < 1e-6; });
  };
  CHECK(has({0.01f, 0.01f, 0}));                 // the half of the shared edge
  CHECK(has({0.02f * 2 / 3, 0.02f / 3, 0}));     // its thirds
  CHECK(has({0.02f / 3, 0.02f * 2 / 3, 0}));
  // 4 vertices; the small triangle's 3 edge halves; the long one's 3 edges in thirds (2 points
  // each) and 1 inner point.
  CHECK(samples.size() == 4 + 3 + 3 * 2 + 1);
}
