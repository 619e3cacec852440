// SPDX-License-Identifier: GPL-3.0-or-later
// Scenario files: what a valid file turns into, and that every kind of bad input is an
// InputError naming the file, the line and the dotted key.
#include "harness/formats/scenario_yaml.hpp"
#include "sim/trajectory.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cctype>

using sonomap::harness::load_scenario;
using sonomap::sim::PrimitiveSpec;
using sonomap::test::input_error_of;
using sonomap::test::kBase;
using sonomap::test::with_line;
using sonomap::test::with_lines;
using sonomap::test::ScratchDir;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The message names the file, the line and the key.
void check_located(const std::string& message, const std::string& file, int line,
                   const std::string& key) {
  INFO(message);
  CHECK(message.find(file + ":" + std::to_string(line) + ":") != std::string::npos);
  CHECK(message.find("'" + key + "'") != std::string::npos);
}

std::string error_for(const ScratchDir& dir, const std::string& text,
                      const std::vector<std::string>& overrides = {}) {
  const auto file = dir.write("probe.yaml", text);
  return input_error_of([&] { load_scenario(file, overrides); });
}

const std::string kPlyHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

}  // namespace

TEST_CASE("a valid scenario gives the stated objects, camera and trajectory in SI units",
          "[scenario]") {
  ScratchDir dir("scenario");
  const auto file = dir.write("probe.yaml", kBase);
  const auto s = load_scenario(file);
  CHECK(s.name == "probe");
  CHECK(s.frames == 3);
  CHECK(s.camera.fx == 525.0);
  CHECK(s.camera.cy == 239.5);
  CHECK(s.camera.max_range == 5.0);
  CHECK(s.noise.model == sonomap::sim::NoiseSpec::Model::None);
  REQUIRE(s.statics.size() == 1);
  CHECK(s.statics[0].shape.kind == PrimitiveSpec::Kind::Room);
  CHECK(s.statics[0].shape.size.isApprox(Eigen::Vector3d(4, 4, 2.5)));
  CHECK_FALSE(s.statics[0].mesh.triangles.empty());  // primitives come back triangulated
  REQUIRE(s.body.keyframes.size() == 2);
  // yaw 90 degrees: the body's x axis points along world +y.
  const Eigen::Vector3d x_axis = s.body.keyframes[1].orientation * Eigen::Vector3d::UnitX();
  CHECK(x_axis.isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  CHECK(s.body.keyframes[1].position.isApprox(Eigen::Vector3d(1, 0, 1.5)));
}

TEST_CASE("angles: yaw turns left, positive pitch tilts the forward axis down", "[scenario]") {
  const auto q_yaw = sonomap::harness::quaternion_from_ypr_degrees(90, 0, 0);
  CHECK((q_yaw * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  const auto q_pitch = sonomap::harness::quaternion_from_ypr_degrees(0, 90, 0);
  CHECK((q_pitch * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  const auto q_roll = sonomap::harness::quaternion_from_ypr_degrees(0, 0, 90);
  CHECK((q_roll * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));

  // A camera mounted 15 degrees down looks along (cos 15, 0, -sin 15) in the body frame.
  ScratchDir dir("scenario");
  const auto s = load_scenario(dir.write("probe.yaml", with_line(6, "  max_range: 5.0\n"
                                                                    "  mounting: {pitch: 15, position: [0.1, 0, 0]}")));
  const Eigen::Vector3d optical_z = s.camera.body_T_camera.linear().col(2);
  const double a = 15.0 * kPi / 180.0;
  CHECK(optical_z.isApprox(Eigen::Vector3d(std::cos(a), 0, -std::sin(a)), 1e-12));
  // Optical x stays "right" (body -y).
  CHECK(s.camera.body_T_camera.linear().col(0).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  CHECK(s.camera.body_T_camera.translation().isApprox(Eigen::Vector3d(0.1, 0, 0)));
}

TEST_CASE("duration at the sensor rate gives the frame count", "[scenario]") {
  ScratchDir dir("scenario");
  const auto s = load_scenario(dir.write("probe.yaml", with_line(2, "duration: 2.5")));
  CHECK(s.frames == 75);  // 2.5 s at the default 30 Hz
}

TEST_CASE("mesh files load relative to the scenario, scaled, in PLY, OBJ and STL", "[scenario]") {
  ScratchDir dir("scenario");
  dir.write("meshes/tri.ply", kPlyHeader + "0 0 0\n1 0 0\n0 2 0\n3 0 1 2\n");
  dir.write("meshes/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n");
  dir.write("meshes/tri.stl",
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 2 0\n"
            "endloop\nendfacet\nendsolid t\n");
  for (const std::string ext : {"ply", "obj", "stl"}) {
    SECTION(ext) {
      const auto s = load_scenario(dir.write(
          "probe.yaml", kBase + "  - name: tri\n    mesh: {file: meshes/tri." + ext +
                            ", scale: 2}\n    pose: {position: [1, 0, 0]}\n"));
      REQUIRE(s.statics.size() == 2);
      const auto& mesh = s.statics[1].mesh;
      REQUIRE(mesh.triangles.size() == 1);
      REQUIRE(mesh.vertices.size() == 3);
      // Extents 1 x 2 scaled by 2.
      Eigen::Vector3f hi = mesh.vertices[0], lo = mesh.vertices[0];
      for (const auto& v : mesh.vertices) {
        hi = hi.cwiseMax(v);
        lo = lo.cwiseMin(v);
      }
      CHECK((hi - lo).isApprox(Eigen::Vector3f(2, 4, 0)));
      CHECK(s.statics[1].shape.kind == PrimitiveSpec::Kind::Mesh);
    }
  }
}

TEST_CASE("moving objects keep their trajectory and appear/disappear times", "[scenario]") {
  ScratchDir dir("scenario");
  const auto s = load_scenario(dir.write(
      "probe.yaml", kBase + "moving:\n"
                            "  - name: ball\n"
                            "    sphere: {radius: 0.3, segments: 16}\n"
                            "    appear: 0.5\n"
                            "    disappear: 2\n"
                            "    trajectory:\n"
                            "      interpolation: linear_slerp\n"
                            "      keyframes:\n"
                            "        - {time: 0, position: [1, -1, 1]}\n"
                            "        - {time: 2, position: [1, 1, 1], quaternion: [0, 0, 0.7071067811865476, 0.7071067811865476]}\n"));
  REQUIRE(s.movers.size() == 1);
  const auto& ball = s.movers[0];
  CHECK(ball.shape.kind == PrimitiveSpec::Kind::Sphere);
  CHECK(ball.shape.segments == 16);
  CHECK(ball.appear_time == 0.5);
  CHECK(ball.disappear_time == 2.0);
  // Halfway, the ball is halfway: (1, 0, 1).
  const auto mid = sonomap::sim::pose_at(ball.trajectory, 1.0);
  CHECK(mid.translation().isApprox(Eigen::Vector3d(1, 0, 1), 1e-12));
  CHECK((ball.trajectory.keyframes[1].orientation * Eigen::Vector3d::UnitX())
            .isApprox(Eigen::Vector3d::UnitY(), 1e-9));
}

TEST_CASE("overrides change the document before validation", "[scenario]") {
  ScratchDir dir("scenario");
  const auto file = dir.write("probe.yaml", with_line(2, "duration: 10"));
  const auto s = load_scenario(
      file, {"frames=60", "seed=7", "sensor.noise.model=kinect", "sensor.noise.dropout=0.25",
             "static.0.room.size=[5, 6, 3]", "body.keyframes.1.yaw=45", "static.room.pose={position: [1, 2, 0]}"});
  CHECK(s.frames == 60);  // frames replaces the file's duration
  CHECK(s.seed == 7u);
  CHECK(s.noise.model == sonomap::sim::NoiseSpec::Model::Kinect);
  CHECK(s.noise.dropout == 0.25);
  CHECK(s.statics[0].shape.size.isApprox(Eigen::Vector3d(5, 6, 3)));
  CHECK(s.statics[0].pose.translation().isApprox(Eigen::Vector3d(1, 2, 0)));
  const Eigen::Vector3d x_axis = s.body.keyframes[1].orientation * Eigen::Vector3d::UnitX();
  CHECK(x_axis.isApprox(Eigen::Vector3d(1, 1, 0).normalized(), 1e-12));
}

TEST_CASE("head: yaw and pitch keyframes relative to the body or the world, linear in time",
          "[scenario][head]") {
  ScratchDir dir("scenario");
  CHECK_FALSE(load_scenario(dir.write("probe.yaml", kBase)).head);  // follows the body
  const auto s = load_scenario(dir.write(
      "head.yaml", kBase + "head:\n  keyframes:\n    - {time: 1, yaw: 0}\n"
                           "    - {time: 3, yaw: 270, pitch: -10}\n"));
  REQUIRE(s.head);
  CHECK_FALSE(s.head->absolute);
  CHECK(s.head->at(0.0).yaw_deg == 0.0);    // held before the first keyframe
  CHECK(s.head->at(2.0).yaw_deg == 135.0);  // no wrap: three quarters of a turn left
  CHECK(s.head->at(2.0).pitch_deg == -5.0);
  CHECK(s.head->at(9.0).yaw_deg == 270.0);
  const auto w = load_scenario(dir.write(
      "world.yaml", kBase + "head:\n  relative_to: world\n  keyframes:\n    - {time: 0, yaw: 45}\n"));
  CHECK(w.head->absolute);
  const std::string file = (dir.path() / "probe.yaml").string();
  check_located(error_for(dir, kBase + "head:\n  relative_to: neck\n  keyframes: [{time: 0}]\n"),
                file, 16, "head.relative_to");
  check_located(error_for(dir, kBase + "head:\n  keyframes:\n    - {time: 0, pitch: 95}\n"), file,
                17, "head.keyframes[0].pitch");
  check_located(error_for(dir, kBase + "head:\n  keyframes:\n    - {time: 2}\n    - {time: 1}\n"),
                file, 18, "head.keyframes[1].time");
}

TEST_CASE("bad input: each error names the file, the line and the key", "[scenario][bad-input]") {
  ScratchDir dir("scenario");
  const std::string file = (dir.path() / "probe.yaml").string();

  SECTION("unknown key") {
    check_located(error_for(dir, with_line(4, "  intrinsic: {fx: 525, fy: 525, cx: 319.5, cy: 239.5}")),
                  file, 4, "sensor.intrinsic");
    check_located(error_for(dir, with_line(4, "  intrinsics: {fxx: 525, fy: 525}")), file, 4,
                  "sensor.intrinsics.fxx");
    check_located(error_for(dir, kBase + "colour: red\n"), file, 15, "colour");
  }
  SECTION("wrong type") {
    check_located(error_for(dir, with_line(6, "  max_range: far")), file, 6, "sensor.max_range");
    check_located(error_for(dir, with_line(2, "frames: 2.5")), file, 2, "frames");
    check_located(error_for(dir, with_line(10, "    - {time: 0, position: [0, 0], yaw: 0}")), file,
                  10, "body.keyframes[0].position");
    check_located(error_for(dir, with_line(14, "    room: [4, 4, 2.5]")), file, 14, "static[0].room");
  }
  SECTION("missing required key") {
    // Line 8 left blank: the body map starts with `keyframes` on line 9.
    check_located(error_for(dir, with_lines(8, 8, "")), file, 9, "body.interpolation");
    check_located(error_for(dir, with_line(14, "    box: {}")), file, 14, "static[0].box.size");
    check_located(error_for(dir, with_line(14, "    pose: {}")), file, 13, "static[0]");
  }
  SECTION("zero or negative intrinsics") {
    check_located(error_for(dir, with_line(4, "  intrinsics: {fx: 0, fy: 525, cx: 319.5, cy: 239.5}")),
                  file, 4, "sensor.intrinsics.fx");
    check_located(error_for(dir, with_line(4, "  intrinsics: {fx: 525, fy: -1, cx: 319.5, cy: 239.5}")),
                  file, 4, "sensor.intrinsics.fy");
    check_located(error_for(dir, with_line(4, "  intrinsics: {cx: -3}")), file, 4,
                  "sensor.intrinsics.cx");
  }
  SECTION("an image size no camera has") {
    check_located(error_for(dir, with_line(6, "  max_range: 5.0\n  width: 100000")), file, 7,
                  "sensor.width");
  }
  SECTION("max range not above min range") {
    check_located(error_for(dir, with_line(6, "  max_range: 0.3")), file, 6, "sensor.max_range");
  }
  SECTION("keyframe times not increasing") {
    check_located(error_for(dir, with_line(11, "    - {time: 0, position: [1, 0, 1.5]}")), file, 11,
                  "body.keyframes[1].time");
  }
  SECTION("a half turn between keyframes is ambiguous") {
    check_located(error_for(dir, with_line(11, "    - {time: 1, position: [1, 0, 1.5], yaw: 180}")),
                  file, 11, "body.keyframes[1].yaw");
  }
  SECTION("empty trajectory") {
    check_located(error_for(dir, with_lines(9, 11, "  keyframes: []")), file, 9, "body.keyframes");
  }
  SECTION("frames <= 0, or both frames and duration") {
    check_located(error_for(dir, with_line(2, "frames: 0")), file, 2, "frames");
    check_located(error_for(dir, with_line(2, "frames: -4")), file, 2, "frames");
    check_located(error_for(dir, with_line(2, "frames: 3\nduration: 1")), file, 3, "duration");
  }
  SECTION("unknown interpolation or noise model") {
    check_located(error_for(dir, with_line(8, "  interpolation: cubic")), file, 8,
                  "body.interpolation");
    check_located(error_for(dir, with_line(6, "  max_range: 5\n  noise: {model: kinnect}")), file, 7,
                  "sensor.noise.model");
  }
  SECTION("a key given twice") {
    check_located(error_for(dir, with_line(6, "  max_range: 5\n  max_range: 6")), file, 7,
                  "sensor.max_range");
  }
  SECTION("missing mesh file") {
    const std::string message = error_for(dir, kBase + "  - name: cow\n    mesh: {file: nowhere/cow.ply}\n");
    check_located(message, file, 16, "static[1].mesh.file");
    CHECK(message.find("cow.ply") != std::string::npos);
    CHECK(message.find("does not exist") != std::string::npos);
  }
  SECTION("mesh with a NaN vertex") {
    dir.write("bad.ply", kPlyHeader + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n");
    const std::string message = error_for(dir, kBase + "  - name: bad\n    mesh: {file: bad.ply}\n");
    check_located(message, file, 16, "static[1].mesh.file");
    CHECK(message.find("vertex 1") != std::string::npos);
  }
  SECTION("mesh file that is not a mesh") {
    dir.write("junk.ply", "this is not a mesh\n");
    check_located(error_for(dir, kBase + "  - name: junk\n    mesh: {file: junk.ply}\n"), file, 16,
                  "static[1].mesh.file");
  }
  SECTION("two objects with one name") {
    check_located(error_for(dir, kBase + "  - name: room\n    box: {size: [1, 1, 1]}\n"), file, 15,
                  "static[1].name");
  }
  SECTION("disappear before appear") {
    check_located(
        error_for(dir, kBase + "moving:\n  - name: b\n    box: {size: [1, 1, 1]}\n    appear: 3\n"
                               "    disappear: 1\n    trajectory: {interpolation: linear_slerp, "
                               "keyframes: [{time: 0, position: [0, 0, 0]}]}\n"),
        file, 19, "moving[0].disappear");
  }
}

TEST_CASE("bad input: malformed YAML, empty and missing files", "[scenario][bad-input]") {
  ScratchDir dir("scenario");
  const std::string file = (dir.path() / "probe.yaml").string();
  const std::string malformed = error_for(dir, with_line(4, "  intrinsics: {fx: 525, fy: [525"));
  INFO(malformed);
  CHECK(malformed.find("malformed YAML") != std::string::npos);
  const std::size_t at = malformed.find(file + ":");
  REQUIRE(at != std::string::npos);
  CHECK(std::isdigit(static_cast<unsigned char>(malformed[at + file.size() + 1])));

  CHECK(error_for(dir, "").find("empty") != std::string::npos);
  const std::string missing =
      input_error_of([&] { load_scenario(dir.path() / "absent.yaml"); });
  CHECK(missing.find("absent.yaml") != std::string::npos);
}

TEST_CASE("bad input from an override names the override", "[scenario][bad-input]") {
  ScratchDir dir("scenario");
  const auto file = dir.write("probe.yaml", kBase);
  const std::string unknown =
      input_error_of([&] { load_scenario(file, {"sensor.nosie.model=kinect"}); });
  INFO(unknown);
  CHECK(unknown.find("--set 'sensor.nosie.model=kinect'") != std::string::npos);
  CHECK(unknown.find("'sensor.nosie'") != std::string::npos);

  const std::string zero = input_error_of([&] { load_scenario(file, {"sensor.intrinsics.fx=0"}); });
  INFO(zero);
  CHECK(zero.find("--set 'sensor.intrinsics.fx=0'") != std::string::npos);
  CHECK(zero.find("'sensor.intrinsics.fx'") != std::string::npos);

  CHECK(input_error_of([&] { load_scenario(file, {"frames"}); }).find("key=value") != std::string::npos);
  CHECK(input_error_of([&] { load_scenario(file, {"static.3.box.size=[1,1,1]"}); })
            .find("no such item") != std::string::npos);
  CHECK(input_error_of([&] { load_scenario(file, {"name.first=x"}); }).find("--set 'name.first=x'") !=
        std::string::npos);
  CHECK(input_error_of([&] { load_scenario(file, {"frames=[1"}); }).find("not valid YAML") !=
        std::string::npos);
}
