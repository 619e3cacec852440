// SPDX-License-Identifier: GPL-3.0-or-later
// A 7-Scenes-style folder (16-bit millimetre PNGs, one 4x4 camera-to-world pose file per frame,
// a y-up world) described by a sequence file runs end to end, and its circle equals the run on
// the TUM render it was converted from within the millimetre quantisation. Bad sequence files
// fail with the file, line and key, or every missing file at once, and leave nothing behind.
#include "test_sequence_support.hpp"

#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/sequence_io.hpp"
#include "harness/formats/tum_io.hpp"

#include <cmath>
#include <fstream>

namespace fs = std::filesystem;
using namespace sonomap;

namespace {

// Renders the smoke scene as TUM into dir/tum and converts it to dir/seven: millimetre PNGs and
// 4x4 pose files of a world turned so that its up axis is +y (world' = Rx(-90 deg) world), and
// then by `tilt` (a recording whose world axes are not the room's).
void make_seven_scenes_folder(const fs::path& dir, const Eigen::Matrix3d& tilt = Eigen::Matrix3d::Identity(),
                              const std::vector<std::string>& keys = {}) {
  std::vector<std::string> render = {"--quiet", "render", test::shipped("scenes/smoke.yaml").string(),
                                     "--out", (dir / "tum").string(), "--frames", "6"};
  for (const auto& key : keys) render.insert(render.end(), {"--set", key});
  for (const auto& key : test::small_camera_keys()) render.insert(render.end(), {"--set", key});
  REQUIRE(test::run_sonomap(render).status == 0);
  fs::create_directories(dir / "seven");
  Eigen::Matrix4d y_up = Eigen::Matrix4d::Identity();
  y_up.topLeftCorner<3, 3>() << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // z -> +y, exact
  y_up.topLeftCorner<3, 3>() = tilt * y_up.topLeftCorner<3, 3>().eval();
  std::ifstream depth_list(dir / "tum/depth.txt"), groundtruth(dir / "tum/groundtruth.txt");
  std::string line, pose_line;
  for (int i = 0; std::getline(depth_list, line);) {
    if (line.empty() || line[0] == '#') continue;
    do std::getline(groundtruth, pose_line); while (pose_line[0] == '#');
    const std::string name = line.substr(line.find(' ') + 1);
    harness::DepthImage16 image = harness::read_png16(dir / "tum" / name);
    for (auto& v : image.pixels) v = static_cast<std::uint16_t>(std::lround(v / 5.0));  // 1/5000 m -> mm
    char stem[32];
    std::snprintf(stem, sizeof stem, "frame-%06d", i++);
    harness::write_png16(dir / "seven" / (std::string(stem) + ".depth.png"), image);
    double t, x, y, z, qx, qy, qz, qw;
    std::istringstream(pose_line) >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    m.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, z);
    m = y_up * m;
    std::ofstream pose(dir / "seven" / (std::string(stem) + ".pose.txt"));
    for (int r = 0; r < 4; ++r) {
      char row[128];
      std::snprintf(row, sizeof row, "%.17g %.17g %.17g %.17g\n", m(r, 0), m(r, 1), m(r, 2), m(r, 3));
      pose << row;
    }
  }
}

// The sequence file of that folder; `depth_scale` empty leaves the key out.
std::string sequence_text(const fs::path& dir, const std::string& depth_scale, const std::string& fx = "262.5",
                          const std::string& world = "{up: +y, floor: 0}") {
  const Eigen::Isometry3d mount = harness::load_camera_file(dir / "tum/camera.yaml").camera.body_T_camera;
  return "sequence:\n"
         "  name: seven-style\n"
         "  source: folder\n"
         "  path: seven\n"
         "  depth: {pattern: 'frame-######.depth.png', encoding: 16UC1" +
         (depth_scale.empty() ? "" : ", scale: " + depth_scale) + "}\n" +
         "  frames: {first: 0, count: 6}\n"
         "  camera:\n"
         "    width: 320\n"
         "    height: 240\n"
         "    intrinsics: {fx: " + fx + ", fy: 262.5, cx: 159.5, cy: 119.5}\n"
         "    min_range: 0.3\n"
         "    max_range: 5.0\n"
         "    body_T_camera: " + test::yaml_matrix(mount.matrix()) + "\n"
         "  poses: {format: matrix4x4, pattern: 'frame-######.pose.txt'}\n"
         "  world: " + world + "\n";
}

void write_text(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

test::CliResult run_cli(const fs::path& sequence, const fs::path& out) {
  return test::run_sonomap({"--quiet", "run", sequence.string(), "--out", out.string(), "--frames", "2"});
}

}  // namespace

TEST_CASE("a 7-Scenes-style folder runs from its sequence file and matches the TUM run",
          "[sequence][folder]") {
  test::ScratchDir scratch("sequence-folder");
  make_seven_scenes_folder(scratch.path());
  write_text(scratch.path() / "kitchen.yaml", sequence_text(scratch.path(), "1000"));
  const auto tum = test::run_quietly(scratch.path() / "tum", scratch.path() / "run-tum");
  const auto seven = test::run_quietly(scratch.path() / "kitchen.yaml", scratch.path() / "run-seven");
  CHECK(seven["ground_truth"] == false);
  CHECK(seven["scenario"]["name"] == "seven-style");
  // z rounded to the millimetre moves by at most 0.5 mm from the 1/5000 m value, a point along
  // its ray by 1.255 x that at this camera's corners (see test_run_recorded.cpp).
  const int known = test::compare_circles(test::circle_of(scratch.path() / "run-tum/circle.csv", 5),
                                          test::circle_of(scratch.path() / "run-seven/circle.csv", 5),
                                          0.5e-3 * 1.255 + 1e-6);
  CHECK(known > 40);
}

TEST_CASE("floor: auto finds a tilted recording's floor and up axis", "[sequence][folder]") {
  test::ScratchDir scratch("sequence-folder-tilted");
  // 20 degrees about an axis between x and z: no world axis is up any more.
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d(1, 0, 1).normalized()).toRotationMatrix();
  // Without the Kinect noise: the floor this camera sees is a strip 2.2 to 3 m away, where the
  // noise alone tilts a plane fit by a few tenths of a degree; the quantisation stays.
  make_seven_scenes_folder(scratch.path(), tilt, {"sensor.noise.model=none"});
  write_text(scratch.path() / "tilted.yaml", sequence_text(scratch.path(), "1000", "262.5", "{floor: auto, floor_frames: 3}"));
  auto sequence = harness::open_recorded_sequence(scratch.path() / "tilted.yaml");
  for (int i : {0, 5}) {
    INFO("frame " << i);
    const Frame frame = sequence->frame(i);
    // The smoke listener stands 1.5 m above the floor with the camera pitched 10 degrees down
    // (scenes/smoke.yaml), whatever the recording's axes. This camera sees the floor only as a
    // strip 2.2 to 3 m away, ending at a wall whose foot lies within the fit's 3 cm inlier
    // distance: the plane comes out tilted by about a quarter of a degree (measured 0.26) and
    // 1 cm high. A box top (0.5 and 0.8 m) or a plane leaning on the walls would be far off.
    CHECK(frame.world_T_body.translation().z() - sequence->ground_z() == Approx(1.5).margin(0.02));
    const Eigen::Vector3d optical_axis = frame.world_T_camera.linear().col(2);
    CHECK(std::asin(-optical_axis.z()) * 180.0 / M_PI == Approx(10.0).margin(0.5));
  }
  // And the circle is the TUM run's within the millimetre quantisation plus the plane fit's
  // tilt (under 0.5 degrees: a point 1.5 m above or below the listener moves by 1.3 cm).
  const auto tum = test::run_quietly(scratch.path() / "tum", scratch.path() / "run-tum");
  const auto tilted = test::run_quietly(scratch.path() / "tilted.yaml", scratch.path() / "run-tilted");
  const auto a = test::circle_of(scratch.path() / "run-tum/circle.csv", 5);
  const auto b = test::circle_of(scratch.path() / "run-tilted/circle.csv", 5);
  int both = 0, close = 0;
  for (int k = 0; k < 360; ++k) {
    if (a.at(k).empty() || b.at(k).empty()) continue;
    ++both;
    close += std::abs(std::stod(a.at(k)) - std::stod(b.at(k))) <= 0.015;
  }
  CHECK(both > 40);
  CHECK(close >= both * 95 / 100);
}

TEST_CASE("bad folder sequences fail with file, line and key, and write nothing", "[sequence][folder]") {
  test::ScratchDir scratch("sequence-folder-bad");
  make_seven_scenes_folder(scratch.path());
  const fs::path sequence = scratch.path() / "sequence.yaml";
  const fs::path out = scratch.path() / "out";

  // The run exits 2 and its message holds every one of `parts`.
  const auto fails_with = [&](const std::string& text, const std::vector<std::string>& parts) {
    write_text(sequence, text);
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    for (const auto& part : parts) CHECK_THAT(result.output, Catch::Contains(part));
  };
  SECTION("every missing file is named at once") {
    fs::remove(scratch.path() / "seven/frame-000002.depth.png");
    fs::remove(scratch.path() / "seven/frame-000004.pose.txt");
    fails_with(sequence_text(scratch.path(), "1000"),
               {"2 files missing", "frame-000002.depth.png", "frame-000004.pose.txt"});
  }
  SECTION("a forgotten depth scale is an error with the hint") {
    fails_with(sequence_text(scratch.path(), ""), {"sequence.depth.scale", "millimetre PNGs: 1000"});
  }
  SECTION("millimetres read as metres give an implausible median depth") {
    fails_with(sequence_text(scratch.path(), "1"), {"median depth", "check depth.scale"});
  }
  SECTION("a number out of range names its line and key") {
    fails_with(sequence_text(scratch.path(), "1000", "-5"),
               {"sequence.yaml:10", "sequence.camera.intrinsics.fx"});
  }
  CHECK(test::nothing_written(out));
}
