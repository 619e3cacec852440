// SPDX-License-Identifier: GPL-3.0-or-later
// Marching a (distance, weight) grid leaf by leaf (core/marching_cubes.hpp): a leaf's cubes
// reach one voxel into its upper neighbours, whether those are leaves or tiles, and a change on
// a leaf's lower faces dirties the lower neighbours whose cubes reach it.
#include "core/marching_cubes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace sonomap;

namespace {

constexpr double kVoxel = 0.05;
constexpr double kPlaneZ = 0.39;  // between the centres of voxel rows z = 7 (0.375) and 8 (0.425)

// A horizontal surface at kPlaneZ over 16 x 16 voxel columns, observed (weight 1) from z = 0 to
// 15: distance z - kPlaneZ at each voxel centre, positive behind it (above). The rows z = 0-7 are
// set voxel by voxel (leaves); the rows 8-15 either the same way or, with `upper_as_tiles`, as
// one fill of their value at z = 8 (OpenVDB stores a filled 8^3 block as a tile, not a leaf).
DistanceWeightGrid::Ptr plane_grid(bool upper_as_tiles) {
  auto grid = DistanceWeightGrid::create(openvdb::Vec2s(-1.0f, 0.0f));
  auto acc = grid->getAccessor();
  auto value_at = [](int z) { return openvdb::Vec2s(static_cast<float>((z + 0.5) * kVoxel - kPlaneZ), 1.0f); };
  for (int x = 0; x < 16; ++x)
    for (int y = 0; y < 16; ++y)
      for (int z = 0; z < (upper_as_tiles ? 8 : 16); ++z) acc.setValue(openvdb::Coord(x, y, z), value_at(z));
  if (upper_as_tiles)
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0, 0, 8), openvdb::Coord(15, 15, 15)), value_at(8));
  return grid;
}

}  // namespace

TEST_CASE("a plane between two leaves' voxel rows is met by the lower leaves' cubes, at its height, "
          "whether the upper neighbours are leaves or tiles",
          "[surface][marching]") {
  for (const bool tiles : {false, true}) {
    INFO((tiles ? "upper neighbours are tiles" : "upper neighbours are leaves"));
    const auto grid = plane_grid(tiles);
    CHECK(grid->tree().leafCount() == (tiles ? 4u : 8u));
    size_t triangles = 0, vertices = 0;
    for (int leaf = 0; leaf < 8; ++leaf) {
      const openvdb::Coord origin((leaf & 4) ? 8 : 0, (leaf & 2) ? 8 : 0, (leaf & 1) ? 8 : 0);
      SurfaceMesh mesh;
      march_leaf(*grid, origin, kVoxel, 0.5f, mesh);
      if (origin.z() == 8) CHECK(mesh.triangles.empty());  // wholly behind the surface
      for (const Eigen::Vector3f& v : mesh.vertices) CHECK(std::abs(v.z() - kPlaneZ) < 1e-6);
      triangles += mesh.triangles.size();
      vertices += mesh.vertices.size();
    }
    // The cubes at z = 7 whose 8 corners are observed: 15 x 15 (the 16th column has no
    // neighbour), two triangles each. Each leaf keeps its own copy of the vertices on the
    // columns x = 8 and y = 8 that it shares: 16 x 16 columns, plus 16 + 16 + 1 repeats.
    CHECK(triangles == 2u * 15u * 15u);
    CHECK(vertices == 16u * 16u + 16u + 16u + 1u);
  }
}

TEST_CASE("a changed voxel dirties its leaf and, on the leaf's lower faces, the lower neighbours "
          "whose cubes reach it",
          "[surface][marching]") {
  using Leaf = DistanceWeightGrid::TreeType::LeafNodeType;
  const openvdb::Coord origin(8, 8, 8);
  auto dirtied_by = [&](int x, int y, int z) {  // x, y, z within the leaf at `origin`
    LeafChanges change{origin, LeafMask()};
    change.voxels.setOn(Leaf::coordToOffset(openvdb::Coord(x, y, z)));
    return dirty_leaves({change});
  };
  using Coords = std::vector<openvdb::Coord>;
  CHECK(dirtied_by(3, 4, 5) == Coords{origin});
  CHECK(dirtied_by(7, 7, 7) == Coords{origin});
  CHECK(dirtied_by(0, 4, 5) == Coords{{0, 8, 8}, origin});
  CHECK(dirtied_by(3, 0, 5) == Coords{{8, 0, 8}, origin});
  CHECK(dirtied_by(3, 4, 0) == Coords{{8, 8, 0}, origin});
  CHECK(dirtied_by(0, 4, 0) == Coords{{0, 8, 0}, {0, 8, 8}, {8, 8, 0}, origin});
  CHECK(dirtied_by(0, 0, 0) ==
        Coords{{0, 0, 0}, {0, 0, 8}, {0, 8, 0}, {0, 8, 8}, {8, 0, 0}, {8, 0, 8}, {8, 8, 0}, origin});
  // Two voxels on two different faces: each face's neighbour, not their common corner's.
  LeafChanges two{origin, LeafMask()};
  two.voxels.setOn(Leaf::coordToOffset(openvdb::Coord(0, 4, 5)));
  two.voxels.setOn(Leaf::coordToOffset(openvdb::Coord(3, 0, 5)));
  CHECK(dirty_leaves({two}) == Coords{{0, 8, 8}, {8, 0, 8}, origin});
  // No change, no dirty leaf.
  CHECK(dirty_leaves({LeafChanges{origin, LeafMask()}}).empty());
}
