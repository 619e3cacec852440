// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/mesh_io.hpp"

#include "harness/formats/modules.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/subprocess.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

// The bytes of a PLY scalar type; 0 for a type PLY does not define.
std::uint64_t ply_type_bytes(const std::string& type) {
  static const std::map<std::string, std::uint64_t> kSizes = {
      {"char", 1},  {"uchar", 1},  {"int8", 1},  {"uint8", 1},   {"short", 2},   {"ushort", 2},
      {"int16", 2}, {"uint16", 2}, {"int", 4},   {"uint", 4},    {"int32", 4},   {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto size = kSizes.find(type);
  return size == kSizes.end() ? 0 : size->second;
}

// A PLY header as read for its checks: its elements (name, count, the fewest bytes one takes:
// one per property in ASCII, the properties' sizes in binary, a list at least its count) and
// the bytes after it.
struct PlyHeader {
  struct Element {
    std::string name;
    std::uint64_t count = 0, bytes = 0;
    int line = 0, properties = 0;
  };
  std::vector<Element> elements;
  std::uint64_t body_bytes = 0;
};

// Fails unless the last element read so far has a property: an element needs some to be read.
void check_last_element(const std::string& file, const PlyHeader& header) {
  if (!header.elements.empty() && header.elements.back().properties == 0)
    throw InputError(file, header.elements.back().line, "element", "has no properties");
}

// Reads header line `number` (after "ply") into `header`; `ascii` follows the format line.
void read_ply_header_line(const std::string& file, const std::string& line, int number, bool& ascii,
                          PlyHeader& header) {
  std::istringstream words(line);
  std::string word, type, item, property, extra;
  words >> word;
  auto refuse = [&](const std::string& key, const std::string& what) {
    throw InputError(file, number, key, what + ": '" + printable(line) + "'");
  };
  if (word == "comment" || word == "obj_info") return;
  if (word == "format") {
    words >> type;
    ascii = type == "ascii";
  } else if (word == "element") {
    check_last_element(file, header);
    PlyHeader::Element& e = header.elements.emplace_back();
    e.line = number;
    if (!(words >> e.name >> e.count) || words >> extra) refuse("element", "needs a name and a count, and nothing else");
  } else if (word == "property") {
    if (!(words >> type) || (type == "list" && !(words >> type >> item)) || ply_type_bytes(type) == 0 ||
        (!item.empty() && ply_type_bytes(item) == 0))
      refuse("property", "not a PLY property type");
    if (!(words >> property) || words >> extra) refuse("property", "needs a type and a name, and nothing else");
    if (header.elements.empty()) refuse("property", "comes before any element");
    header.elements.back().bytes += ascii ? 1 : ply_type_bytes(type);
    ++header.elements.back().properties;
  } else {
    refuse("", "not a PLY header line");
  }
}

// Reads the header of a file that starts like a PLY (nullopt for other files). Throws
// InputError naming the line for a header without end_header in its first 64 kB, a line that
// is no PLY header line (format, comment, obj_info, element, property), an element without
// exactly a name and a count or without properties, or a property of a type PLY does not define.
// (Assimp read on through such lines: on a fuzzed header with an element line ending in a NUL
// and junk lines after it, it did not finish within 30 s.)
std::optional<PlyHeader> read_ply_header(const fs::path& file) {
  constexpr std::size_t kMaxHeader = 1 << 16;
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  std::string head(kMaxHeader, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.rfind("ply\n", 0) != 0 && head.rfind("ply\r", 0) != 0) return std::nullopt;
  const std::size_t end = head.find("\nend_header");
  const std::size_t body_at = end == std::string::npos ? end : head.find('\n', end + 1);
  if (body_at == std::string::npos)
    throw InputError(name, 0, "", "the PLY header has no end_header line in its first 64 kB");
  PlyHeader header;
  header.body_bytes = fs::file_size(file) - (body_at + 1);
  bool ascii = true;
  std::istringstream lines(head.substr(0, end + 1));
  std::string line;
  std::getline(lines, line);  // "ply"
  for (int number = 2; std::getline(lines, line); ++number) read_ply_header_line(name, line, number, ascii, header);
  check_last_element(name, header);
  return header;
}

// Assimp's PLY reader trusts the header (as Open3D's reader of point clouds does): it sizes
// its arrays by the element counts before it reads the elements (a 2 kB file claiming 100
// million vertices kept it busy for minutes and gigabytes), and it crashed on a header without
// its end_header line (fuzz/fuzz_mesh). So the header must read (read_ply_header) and its
// counts fit in the bytes after it.
void check_ply_counts(const std::string& file, const PlyHeader& header) {
  std::uint64_t left = header.body_bytes;
  for (const PlyHeader::Element& e : header.elements) {
    if (e.bytes == 0) continue;
    if (e.count > left / e.bytes)
      throw InputError(file, e.line, "element " + e.name,
                       "the header claims " + std::to_string(e.count) + " elements of at least " +
                           std::to_string(e.bytes) + " bytes each; the " + std::to_string(left) +
                           " bytes left after the header cannot hold them");
    left -= e.count * e.bytes;
  }
}

// Fails unless `file` is a regular file and, when named .ply, starts like one (Open3D's rply
// prints its own complaint about a bad header; say it ourselves instead), and unless a PLY
// header (any file that starts like one) reads and its counts fit: both readers trust them.
void check_readable(const fs::path& file, const std::string& what) {
  const std::string name = file.string();
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(name, 0, "", what + " file does not exist");
  if (!fs::is_regular_file(file, ec)) throw InputError(name, 0, "", what + " path is not a file");
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::optional<PlyHeader> header = read_ply_header(file);
  if (header) check_ply_counts(name, *header);
  else if (extension == ".ply") throw InputError(name, 1, "", "not a PLY file (it does not start with 'ply')");
}

constexpr unsigned kMeshSteps = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure;

// The triangles of every mesh in an assimp scene, node transforms applied, or why they are
// no usable mesh (empty when they are).
std::string mesh_of_scene(const aiScene& scene, sim::TriangleMesh& mesh) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& part = *scene.mMeshes[m];
    const int first = static_cast<int>(mesh.vertices.size());
    for (unsigned i = 0; i < part.mNumVertices; ++i) {
      const aiVector3D& v = part.mVertices[i];
      const Eigen::Vector3f p(v.x, v.y, v.z);
      if (!p.allFinite()) return "vertex " + std::to_string(mesh.vertices.size()) + " is not finite (NaN or inf)";
      mesh.vertices.push_back(p);
    }
    for (unsigned f = 0; f < part.mNumFaces; ++f) {
      const aiFace& face = part.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines: no surface
      Eigen::Vector3i t;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= part.mNumVertices)
          return "triangle " + std::to_string(mesh.triangles.size()) + " refers to a vertex that does not exist";
        t[k] = first + static_cast<int>(face.mIndices[k]);
      }
      mesh.triangles.push_back(t);
    }
  }
  return mesh.triangles.empty() ? "the mesh has no triangles" : "";
}

// The child's answer: kMesh and the mesh (vertex and triangle counts, then their coordinates
// and indices), or kRefused and why.
constexpr int kMesh = 0, kRefused = 1, kWriteFailed = 2;
constexpr size_t kMaxReason = 400;  // characters of a refusal shown

template <typename T>
bool write_items(ChildOutput& out, const std::vector<T>& items) {
  return out.write(items.data(), items.size() * sizeof(T));
}

int read_in_child(const fs::path& file, ChildOutput& out) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(file.string(), kMeshSteps);
  sim::TriangleMesh mesh;
  std::string reason = scene ? mesh_of_scene(*scene, mesh)
                             : std::string("cannot read the mesh (") + importer.GetErrorString() + ")";
  if (!reason.empty()) return out.write(reason.data(), reason.size()) ? kRefused : kWriteFailed;
  const uint64_t counts[2] = {mesh.vertices.size(), mesh.triangles.size()};
  return out.write(counts, sizeof counts) && write_items(out, mesh.vertices) && write_items(out, mesh.triangles) ? kMesh
                                                                                                              : kWriteFailed;
}

// The mesh as the child wrote it.
sim::TriangleMesh mesh_from_bytes(const std::string& bytes) {
  uint64_t counts[2] = {0, 0};
  const auto fail = [] { return std::runtime_error("the mesh reader's child process handed over a broken mesh"); };
  if (bytes.size() < sizeof counts) throw fail();
  std::memcpy(counts, bytes.data(), sizeof counts);
  const uint64_t vertex_bytes = counts[0] * sizeof(Eigen::Vector3f), triangle_bytes = counts[1] * sizeof(Eigen::Vector3i);
  if (counts[0] > bytes.size() || counts[1] > bytes.size() || sizeof counts + vertex_bytes + triangle_bytes != bytes.size())
    throw fail();
  sim::TriangleMesh mesh;
  mesh.vertices.resize(counts[0]);
  mesh.triangles.resize(counts[1]);
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) && sizeof(Eigen::Vector3i) == 3 * sizeof(int));
  std::memcpy(mesh.vertices.data()->data(), bytes.data() + sizeof counts, vertex_bytes);
  std::memcpy(mesh.triangles.data()->data(), bytes.data() + sizeof counts + vertex_bytes, triangle_bytes);
  return mesh;
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
// triangles, node transforms applied, every mesh of the file in one. Assimp aborts on some
// corrupt files (an assertion in its triangulation, on a PLY whose vertex lacked z:
// fuzz/fuzz_mesh) and may crash or loop on others, so it reads the file in a child process: a
// crash or a hang there is a clear error here, and the mesh (or why the file is none) comes
// back through a memory file. (The file used to be read again here, which doubled the time of
// a large mesh: 80,000 triangles took 250-330 ms.)
sim::TriangleMesh load_mesh(const fs::path& file) {
  check_readable(file, "mesh");
  ChildOutput out;
  const int found = screen_file(file, "the mesh reader (assimp)", [&] { return read_in_child(file, out); });
  if (found == kWriteFailed) throw std::runtime_error("the mesh reader's child process could not hand over " + file.string());
  const std::string bytes = out.read();
  // Assimp's reasons may quote the file's bytes: shown escaped, as a PLY header line is.
  if (found == kRefused) throw InputError(file.string(), 0, "", printable(bytes, kMaxReason));
  return mesh_from_bytes(bytes);
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
