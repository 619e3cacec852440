// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh files (PLY, OBJ, STL and the other formats assimp reads) as sim::TriangleMesh; point
// clouds through Open3D (loaded on demand: modules.hpp); binary PLY written directly.
#pragma once

#include "sim/scenario.hpp"

#include <filesystem>

namespace sonomap::harness {

// Throws InputError naming the file when it is missing, unreadable, has no triangles, has a
// non-finite vertex (naming its index) or a triangle index out of range.
sim::TriangleMesh load_mesh(const std::filesystem::path& file);

// The points of a point cloud file (PLY, PCD, XYZ; Open3D's readers), e.g. a surveyed scan
// used as ground truth. Throws InputError naming the file when it is missing, unreadable, empty
// or has a non-finite point (naming its index).
std::vector<Eigen::Vector3f> load_point_cloud(const std::filesystem::path& file);

// Writes points as binary PLY (vertices only). Throws std::runtime_error.
void save_point_cloud_ply(const std::filesystem::path& file, const std::vector<Eigen::Vector3f>& points);

// Writes a mesh as binary PLY (the map's surface). Throws std::runtime_error.
void save_mesh_ply(const std::filesystem::path& file, const std::vector<Eigen::Vector3f>& vertices,
                   const std::vector<Eigen::Vector3i>& triangles);

}  // namespace sonomap::harness
