// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/mesh_io.hpp"

#include "harness/support/errors.hpp"

#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/io/TriangleMeshIO.h>
#include <open3d/utility/Logging.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <system_error>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

// Fails unless `file` is a regular file and, when named .ply, starts like one (rply prints its
// own complaint about a bad header; say it ourselves instead).
void check_readable(const fs::path& file, const std::string& what) {
  const std::string name = file.string();
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(name, 0, "", what + " file does not exist");
  if (!fs::is_regular_file(file, ec)) throw InputError(name, 0, "", what + " path is not a file");
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".ply") {
    std::ifstream in(file, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    if (std::string(magic, 3) != "ply" || (magic[3] != '\n' && magic[3] != '\r'))
      throw InputError(name, 1, "", "not a PLY file (it does not start with 'ply')");
  }
}

// Runs an Open3D reader with its logger silenced; fails with our own message naming the file.
// Open3D reports failures through its logger (warnings) or by throwing.
template <typename Read>
void read_quietly(const fs::path& file, const std::string& what, const std::string& formats, Read read) {
  bool ok = false;
  std::string reason = "expected " + formats;
  open3d::utility::VerbosityContextManager silence(open3d::utility::VerbosityLevel::Error);
  silence.Enter();
  try {
    ok = read(file.string());
  } catch (const std::exception& e) {
    reason = e.what();
  }
  silence.Exit();
  if (!ok) throw InputError(file.string(), 0, "", "cannot read the " + what + " (" + reason + ")");
}

}  // namespace

sim::TriangleMesh load_mesh(const fs::path& file) {
  const std::string name = file.string();
  check_readable(file, "mesh");
  open3d::geometry::TriangleMesh loaded;
  read_quietly(file, "mesh", "a PLY, OBJ or STL file",
               [&](const std::string& n) { return open3d::io::ReadTriangleMesh(n, loaded); });
  if (loaded.triangles_.empty() || loaded.vertices_.empty())
    throw InputError(name, 0, "", "the mesh has no triangles");

  sim::TriangleMesh mesh;
  mesh.vertices.reserve(loaded.vertices_.size());
  for (std::size_t i = 0; i < loaded.vertices_.size(); ++i) {
    const Eigen::Vector3d& v = loaded.vertices_[i];
    if (!v.allFinite())
      throw InputError(name, 0, "", "vertex " + std::to_string(i) + " is not finite (NaN or inf)");
    mesh.vertices.push_back(v.cast<float>());
  }
  const int count = static_cast<int>(mesh.vertices.size());
  mesh.triangles.reserve(loaded.triangles_.size());
  for (std::size_t i = 0; i < loaded.triangles_.size(); ++i) {
    const Eigen::Vector3i& t = loaded.triangles_[i];
    if ((t.array() < 0).any() || (t.array() >= count).any())
      throw InputError(name, 0, "", "triangle " + std::to_string(i) +
                                        " refers to a vertex that does not exist");
    mesh.triangles.push_back(t);
  }
  return mesh;
}

std::vector<Eigen::Vector3f> load_point_cloud(const fs::path& file) {
  check_readable(file, "point cloud");
  open3d::geometry::PointCloud loaded;
  read_quietly(file, "point cloud", "a PLY, PCD or XYZ file",
               [&](const std::string& n) { return open3d::io::ReadPointCloud(n, loaded); });
  if (loaded.points_.empty()) throw InputError(file.string(), 0, "", "the point cloud has no points");
  std::vector<Eigen::Vector3f> points;
  points.reserve(loaded.points_.size());
  for (std::size_t i = 0; i < loaded.points_.size(); ++i) {
    if (!loaded.points_[i].allFinite())
      throw InputError(file.string(), 0, "", "point " + std::to_string(i) + " is not finite (NaN or inf)");
    points.push_back(loaded.points_[i].cast<float>());
  }
  return points;
}

void save_point_cloud_ply(const fs::path& file, const std::vector<Eigen::Vector3f>& points) {
  open3d::geometry::PointCloud cloud;
  cloud.points_.reserve(points.size());
  for (const auto& p : points) cloud.points_.push_back(p.cast<double>());
  open3d::utility::VerbosityContextManager silence(open3d::utility::VerbosityLevel::Error);
  silence.Enter();
  const bool ok = open3d::io::WritePointCloud(file.string(), cloud);  // binary, uncompressed
  silence.Exit();
  if (!ok) throw std::runtime_error("cannot write the point cloud " + file.string());
}

void save_mesh_ply(const fs::path& file, const std::vector<Eigen::Vector3f>& vertices,
                   const std::vector<Eigen::Vector3i>& triangles) {
  open3d::geometry::TriangleMesh mesh;
  mesh.vertices_.reserve(vertices.size());
  for (const auto& v : vertices) mesh.vertices_.push_back(v.cast<double>());
  mesh.triangles_ = triangles;
  open3d::utility::VerbosityContextManager silence(open3d::utility::VerbosityLevel::Error);
  silence.Enter();
  const bool ok = open3d::io::WriteTriangleMesh(file.string(), mesh, /*write_ascii=*/false,
                                                /*compressed=*/false, /*write_vertex_normals=*/false,
                                                /*write_vertex_colors=*/false);
  silence.Exit();
  if (!ok) throw std::runtime_error("cannot write the mesh " + file.string());
}

}  // namespace sonomap::harness
