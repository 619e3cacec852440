// SPDX-License-Identifier: GPL-3.0-or-later
// Primitive shapes as triangle meshes, in the object frame:
// - Box: centred in x and y on the origin, z from 0 to size.z (a pose at z = 0 stands it on the
//   floor); triangles wound counter-clockwise seen from outside (normals face out).
// - Room: the same box seen from inside (normals face in).
// - Cylinder: vertical, base at z = 0, `radius`, `height`, `segments` side facets, with caps.
//   Vertices lie on the true circle, so facet midlines are r cos(pi/segments) from the axis.
// - Sphere: a UV sphere centred on the origin, `segments` meridians and segments/2 bands
//   (single-vertex poles); vertices lie on the true sphere.
// - Plane: size.x by size.y in the xy plane, centred on the origin, normal +z.
#pragma once

#include "sim/scenario.hpp"

namespace sonomap::sim {

// Throws std::invalid_argument for non-positive / non-finite sizes, radius, height, fewer
// than 3 segments, or Kind::Mesh (meshes come from files, which the harness loads).
TriangleMesh triangulate(const PrimitiveSpec& shape);

// Throws std::invalid_argument naming the first non-finite vertex or the first triangle with
// an index out of range.
void validate(const TriangleMesh& mesh);

// The mesh an object is traced with: its own mesh if it has one, else its triangulated shape
// (so scenarios built in code may leave `mesh` empty for primitives).
TriangleMesh mesh_of(const PrimitiveSpec& shape, const TriangleMesh& mesh);

}  // namespace sonomap::sim
