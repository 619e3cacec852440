// SPDX-License-Identifier: GPL-3.0-or-later
// The map's PLY files as another program reads them (Open3D's reader, which shares no code with
// sonomap's writer), and Open3D, ROS and netCDF loaded only by the runs that use them.
#include "harness/formats/mesh_io.hpp"
#include "harness/support/subprocess.hpp"
#include "cli_support.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/io/TriangleMeshIO.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <filesystem>
#include <sstream>
#include <string>

using namespace sonomap;
using namespace sonomap::test;
namespace fs = std::filesystem;

namespace {

// A unit tetrahedron 1 km from the origin, so a float's last bits would show in a double.
const Eigen::Vector3f kOffset(1000.125f, -999.5f, 0.0625f);
const std::vector<Eigen::Vector3f> kCorners{kOffset, kOffset + Eigen::Vector3f(1, 0, 0),
                                            kOffset + Eigen::Vector3f(0, 1, 0), kOffset + Eigen::Vector3f(0, 0, 1)};
const std::vector<Eigen::Vector3i> kFaces{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

}  // namespace

TEST_CASE("a mesh written as PLY reads back in Open3D with every vertex and face as written", "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const auto file = dir.path() / "tetra.ply";
  harness::save_mesh_ply(file, kCorners, kFaces);
  open3d::geometry::TriangleMesh read;
  REQUIRE(open3d::io::ReadTriangleMesh(file.string(), read));
  REQUIRE(read.vertices_.size() == 4);
  REQUIRE(read.triangles_.size() == 4);
  for (size_t i = 0; i < 4; ++i) {
    CHECK(read.vertices_[i] == kCorners[i].cast<double>());  // exact: floats widened to doubles
    CHECK(read.triangles_[i] == kFaces[i]);
  }
  // The tetrahedron's volume, 1/6 m^3, from the faces as read: they keep their winding.
  double volume = 0.0;
  for (const auto& t : read.triangles_)
    volume += (read.vertices_[t[0]] - kOffset.cast<double>())
                  .dot((read.vertices_[t[1]] - kOffset.cast<double>()).cross(read.vertices_[t[2]] - kOffset.cast<double>())) / 6.0;
  CHECK(std::abs(volume) == Approx(1.0 / 6.0).epsilon(1e-9));
}

TEST_CASE("points written as PLY read back in Open3D, in order, exactly", "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const auto file = dir.path() / "points.ply";
  harness::save_point_cloud_ply(file, kCorners);
  open3d::geometry::PointCloud read;
  REQUIRE(open3d::io::ReadPointCloud(file.string(), read));
  REQUIRE(read.points_.size() == kCorners.size());
  for (size_t i = 0; i < kCorners.size(); ++i) CHECK(read.points_[i] == kCorners[i].cast<double>());
}

TEST_CASE("a PLY that cannot be written is an error naming the file, not a silent success", "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const auto file = dir.path() / "missing-folder" / "map.ply";
  try {
    harness::save_mesh_ply(file, kCorners, kFaces);
    FAIL("no error");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()).find("missing-folder/map.ply") != std::string::npos);
  }
}

// The files the dynamic loader opened for the process itself, from its log (LD_DEBUG=files: each
// line starts with the pid; the first is the program's own, children forked later have others).
std::string libraries_of_main_process(const std::string& log) {
  std::istringstream lines(log);
  std::string line, main_pid, opened;
  while (std::getline(lines, line)) {
    const size_t colon = line.find(':'), file = line.find("file=");
    if (colon == std::string::npos || file == std::string::npos) continue;
    std::string pid = line.substr(0, colon);
    pid.erase(0, pid.find_first_not_of(' '));
    if (main_pid.empty()) main_pid = pid;
    if (pid == main_pid) opened += line.substr(file) + "\n";
  }
  return opened;
}

TEST_CASE("a run of vdb_gpdf, its sweep and picture included, never loads Open3D, ROS or netCDF",
          "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const std::string scene = std::string(SONOMAP_SOURCE_DIR) + "/scenes/smoke.yaml";
  setenv("LD_DEBUG", "files", 1);
  const CliResult vdb = run_sonomap({"--quiet", "run", scene, "--frames", "2", "--out", (dir.path() / "vdb").string()});
  const CliResult open3d = run_sonomap({"--quiet", "run", scene, "--frames", "2", "--sweeps", "-1",
                                        "--pictures", "-1", "--mapper", "open3d", "--out",
                                        (dir.path() / "open3d").string()});
  unsetenv("LD_DEBUG");
  REQUIRE(vdb.status == 0);
  REQUIRE(open3d.status == 0);
  REQUIRE(fs::exists(dir.path() / "vdb" / "sweeps"));  // the HRIR set was read for the sweep
  const std::string vdb_opened = libraries_of_main_process(vdb.output);
  CHECK(vdb_opened.find("file=libassimp") != std::string::npos);  // the person mesh was read
  CHECK(vdb_opened.find("libOpen3D") == std::string::npos);
  CHECK(vdb_opened.find("librosbag") == std::string::npos);
  CHECK(vdb_opened.find("libnetcdf") == std::string::npos);
  CHECK(libraries_of_main_process(open3d.output).find("file=libOpen3D") != std::string::npos);
}

// fuzz_mesh's first finding (a leak inside assimp, suppressed in ci/lsan.supp): the file is
// still refused cleanly, naming it.
TEST_CASE("an STL file cut off inside a facet is refused naming the file", "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const auto file = dir.write("cut.stl", "solid t\nfacet normal 0 0 1\noutervertex 1 0 0\nvertex 0 2 0\nen");
  const std::string message = input_error_of([&] { harness::load_mesh(file); });
  CHECK(message.find("cut.stl") != std::string::npos);
}

// Assimp sizes its arrays by a PLY header's counts before reading: 100 million vertices
// claimed by a 200-byte file took it minutes and gigabytes (fuzz/fuzz_mesh).
TEST_CASE("a PLY whose header claims more elements than its bytes can hold is refused naming the line",
          "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const std::string header = "ply\nformat ascii 1.0\nelement vertex ";
  const std::string rest = "\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  // Three vertices of three properties, and a face: 3 x 3 + 1 = 10 bytes at least, 26 here.
  CHECK_NOTHROW(harness::load_mesh(dir.write("three.ply", header + "3" + rest)));
  const std::string message =
      input_error_of([&] { harness::load_mesh(dir.write("claims.ply", header + "100000000" + rest)); });
  CHECK(message.find("claims.ply:3: key 'element vertex'") != std::string::npos);
  CHECK(message.find("claims 100000000 elements of at least 3 bytes each") != std::string::npos);
  // Binary: a vertex of three floats is 12 bytes, so 3 vertices need 36 bytes after the header.
  const std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nend_header\n";
  const std::string cut =
      input_error_of([&] { harness::load_mesh(dir.write("cut.ply", binary + std::string(35, '\0'))); });
  CHECK(cut.find("the 35 bytes left after the header cannot hold them") != std::string::npos);
}

// Assimp crashed on a binary PLY whose header never ended (fuzz/fuzz_mesh).
TEST_CASE("a PLY header without its end_header line, or with a property of no PLY type, is refused",
          "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const std::string element = "ply\nformat binary_little_endian 1.0\nelement vertex 1\n";
  const std::string unended =
      input_error_of([&] { harness::load_mesh(dir.write("unended.ply", element + "property double x\nend_head" +
                                                                              std::string(12, '\0'))); });
  CHECK(unended.find("unended.ply: the PLY header has no end_header line") != std::string::npos);
  const std::string untyped = input_error_of(
      [&] { harness::load_mesh(dir.write("untyped.ply", element + "property perty double x\nend_header\n")); });
  CHECK(untyped.find("untyped.ply:4: key 'property': not a PLY property type") != std::string::npos);
}

// Assimp did not finish within 30 s on a fuzzed header whose element line ended in a NUL and
// junk, followed by junk lines (fuzz/fuzz_mesh): a header reads as PLY's keywords or is refused.
TEST_CASE("a PLY header line that is no PLY keyword, or an element line with more than a name and a count, "
          "is refused naming the line",
          "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const std::string format = "ply\nformat ascii 1.0\n";
  const std::string triangle = "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string nul = input_error_of([&] {
    harness::load_mesh(dir.write("nul.ply", format + "element vertex 3" + std::string(1, '\0') + "ply\n" + triangle));
  });
  CHECK(nul.find("nul.ply:3: key 'element': needs a name and a count, and nothing else: 'element vertex 3\\x00ply'") !=
        std::string::npos);
  const std::string junk = input_error_of(
      [&] { harness::load_mesh(dir.write("junk.ply", format + "element vertex 3\nform0.0800\n" + triangle)); });
  CHECK(junk.find("junk.ply:4: not a PLY header line: 'form0.0800'") != std::string::npos);
  const std::string empty = input_error_of([&] {
    harness::load_mesh(dir.write("empty.ply", format + "element vertex 3\n" + triangle.substr(triangle.find("element face"))));
  });
  CHECK(empty.find("empty.ply:3: key 'element': has no properties") != std::string::npos);
  // The same triangle with comment and obj_info lines, and CR LF line ends, loads.
  std::string crlf;
  for (char c : format + "comment a triangle\nobj_info made by hand\nelement vertex 3\n" + triangle) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  const sim::TriangleMesh mesh = harness::load_mesh(dir.write("good.ply", crlf));
  CHECK(mesh.triangles.size() == 1);
}

// Assimp aborted (an assertion in its triangulation) on a binary PLY whose header lost its
// vertices' z (fuzz/fuzz_mesh): the faces are then read from the vertices' bytes. The reader
// runs assimp in a child process first, so the crash is an error naming the file.
TEST_CASE("a mesh file on which assimp crashes is refused naming the file, and the program lives", "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const auto file = dir.path() / "no_z.ply";
  harness::save_mesh_ply(file, kCorners, kFaces);
  std::string bytes = test::text_of(file);
  const std::string z = "property double z\n";
  REQUIRE(bytes.find(z) != std::string::npos);
  bytes.replace(bytes.find(z), z.size(), "");
  const std::string message = input_error_of([&] { harness::load_mesh(dir.write("no_z.ply", bytes)); });
  CHECK(message.find("no_z.ply") != std::string::npos);
  CHECK(message.find("the mesh reader (assimp) crashed on it") != std::string::npos);
}

// Open3D's reader of point clouds sizes its points by the header's count too.
TEST_CASE("a point cloud PLY whose header claims more vertices than its bytes can hold is refused naming the line",
          "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const std::string message = input_error_of([&] {
    harness::load_point_cloud(dir.write("cloud.ply", "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\n"
                                                     "property float y\nproperty float z\nend_header\n0 0 0\n"));
  });
  CHECK(message.find("cloud.ply:3: key 'element vertex'") != std::string::npos);
}

namespace {
// Whether process `pid` is gone (or a zombie waiting for its new parent to reap it).
bool process_gone(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string pid_field, name, state;
  return !(stat >> pid_field >> name >> state) || state == "Z";
}
}  // namespace

// The screening child of a mesh or SOFA file (run_isolated) must not outlive the program: a
// parent killed outright, as libFuzzer ends on a timeout, left a child looping in assimp.
TEST_CASE("a screening child dies with the program that started it", "[mesh_io]") {
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  const pid_t program = ::fork();
  REQUIRE(program >= 0);
  if (program == 0) {  // the program: screens "a file" whose reader never returns
    bool timed_out = false;
    harness::run_isolated(
        [&] {
          const pid_t self = ::getpid();
          if (::write(pipe_fds[1], &self, sizeof self) != sizeof self) return 1;
          for (;;) ::pause();
        },
        600.0, timed_out);
    ::_exit(0);
  }
  pid_t child = 0;
  REQUIRE(::read(pipe_fds[0], &child, sizeof child) == sizeof child);
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
  CHECK_FALSE(process_gone(child));
  ::kill(program, SIGKILL);
  ::waitpid(program, nullptr, 0);
  bool gone = false;
  for (int i = 0; i < 500 && !gone; ++i) {
    gone = process_gone(child);
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!gone) ::kill(child, SIGKILL);  // not left behind by the test either
  CHECK(gone);
}

// The file is read in a child process, which hands the mesh (or why the file is none) back to
// the program: what arrives must be the file's triangles, by their corners, and its refusals.
TEST_CASE("an OBJ of two objects, one a quad, loads as its three triangles; a vertex not finite or no triangle "
          "is refused with that reason",
          "[mesh_io]") {
  ScratchDir dir("mesh-io");
  const sim::TriangleMesh mesh = harness::load_mesh(dir.write(
      "two.obj", "o A\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no B\nv 2 0 0.5\nv 3 0 0.5\nv 3 1.25 0.5\nv 2 1.25 0.5\nf 4 5 6 7\n"));
  using Corners = std::array<std::array<float, 3>, 3>;
  std::vector<Corners> read;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    REQUIRE(t.minCoeff() >= 0);
    REQUIRE(t.maxCoeff() < static_cast<int>(mesh.vertices.size()));
    Corners c;
    for (int k = 0; k < 3; ++k) c[k] = {mesh.vertices[t[k]].x(), mesh.vertices[t[k]].y(), mesh.vertices[t[k]].z()};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());  // the winding kept, the start fixed
    read.push_back(c);
  }
  std::sort(read.begin(), read.end());
  // The quad 4 5 6 7 splits along one of its diagonals; either keeps its corners and winding.
  const Corners triangle{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const std::vector<Corners> along_5_7 = {triangle, {{{2, 0, 0.5f}, {3, 0, 0.5f}, {2, 1.25f, 0.5f}}},
                                          {{{2, 1.25f, 0.5f}, {3, 0, 0.5f}, {3, 1.25f, 0.5f}}}};
  const std::vector<Corners> along_4_6 = {triangle, {{{2, 0, 0.5f}, {3, 0, 0.5f}, {3, 1.25f, 0.5f}}},
                                          {{{2, 0, 0.5f}, {3, 1.25f, 0.5f}, {2, 1.25f, 0.5f}}}};
  auto sorted = [](std::vector<Corners> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  CHECK((read == sorted(along_4_6) || read == sorted(along_5_7)));

  const std::string nan = input_error_of([&] { harness::load_mesh(dir.write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")); });
  CHECK(nan.find("nan.obj") != std::string::npos);
  CHECK(nan.find("vertex 0 is not finite") != std::string::npos);
  const std::string lines = input_error_of([&] { harness::load_mesh(dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n")); });
  CHECK(lines.find("lines.obj") != std::string::npos);
  CHECK(lines.find("the mesh has no triangles") != std::string::npos);
}
