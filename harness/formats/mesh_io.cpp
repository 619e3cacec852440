// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/mesh_io.hpp"

#include "harness/formats/modules.hpp"
#include "harness/support/errors.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
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

// A binary little-endian PLY file: the header, then each element's records as written by
// `body` (a few lines of plumbing rather than loading a PLY library for it).
template <typename Body>
void write_binary_ply(const fs::path& file, const std::string& elements, Body body) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the PLY body is written in host order");
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << "ply\nformat binary_little_endian 1.0\ncomment Created by sonomap\n" << elements
      << "end_header\n";
  body(out);
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

template <typename T>
void put(std::ostream& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.write(bytes, sizeof(T));
}

const char* const kVertexElement = "property double x\nproperty double y\nproperty double z\n";

void put_vertices(std::ostream& out, const std::vector<Eigen::Vector3f>& points) {
  for (const Eigen::Vector3f& p : points)
    for (int k = 0; k < 3; ++k) put<double>(out, p[k]);
}

}  // namespace

// Read with assimp (PLY, OBJ, STL and the other formats it knows), polygons split into
// triangles, node transforms applied, every mesh of the file in one.
sim::TriangleMesh load_mesh(const fs::path& file) {
  const std::string name = file.string();
  check_readable(file, "mesh");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(name, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                     aiProcess_PreTransformVertices |
                                                     aiProcess_ValidateDataStructure);
  if (!scene)
    throw InputError(name, 0, "", std::string("cannot read the mesh (") + importer.GetErrorString() + ")");
  sim::TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    const int first = static_cast<int>(mesh.vertices.size());
    for (unsigned i = 0; i < part.mNumVertices; ++i) {
      const aiVector3D& v = part.mVertices[i];
      const Eigen::Vector3f p(v.x, v.y, v.z);
      if (!p.allFinite())
        throw InputError(name, 0, "", "vertex " + std::to_string(mesh.vertices.size()) + " is not finite (NaN or inf)");
      mesh.vertices.push_back(p);
    }
    for (unsigned f = 0; f < part.mNumFaces; ++f) {
      const aiFace& face = part.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines: no surface
      Eigen::Vector3i t;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= part.mNumVertices)
          throw InputError(name, 0, "", "triangle " + std::to_string(mesh.triangles.size()) +
                                            " refers to a vertex that does not exist");
        t[k] = first + static_cast<int>(face.mIndices[k]);
      }
      mesh.triangles.push_back(t);
    }
  }
  if (mesh.triangles.empty()) throw InputError(name, 0, "", "the mesh has no triangles");
  return mesh;
}

std::vector<Eigen::Vector3f> load_point_cloud(const fs::path& file) {
  check_readable(file, "point cloud");
  return open3d_functions().read_point_cloud(file);
}

void save_point_cloud_ply(const fs::path& file, const std::vector<Eigen::Vector3f>& points) {
  write_binary_ply(file, "element vertex " + std::to_string(points.size()) + "\n" + kVertexElement,
                   [&](std::ostream& out) { put_vertices(out, points); });
}

void save_mesh_ply(const fs::path& file, const std::vector<Eigen::Vector3f>& vertices,
                   const std::vector<Eigen::Vector3i>& triangles) {
  const std::string elements = "element vertex " + std::to_string(vertices.size()) + "\n" + kVertexElement +
                               "element face " + std::to_string(triangles.size()) +
                               "\nproperty list uchar uint vertex_indices\n";
  write_binary_ply(file, elements, [&](std::ostream& out) {
    put_vertices(out, vertices);
    for (const Eigen::Vector3i& t : triangles) {
      put<std::uint8_t>(out, 3);
      for (int k = 0; k < 3; ++k) put<std::uint32_t>(out, static_cast<std::uint32_t>(t[k]));
    }
  });
}

}  // namespace sonomap::harness
