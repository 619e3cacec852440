// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap render` and the TUM RGB-D sequence it writes: depth PNGs hold the known wall
// distance, poses are the true camera poses, the reader gets back what was written, and bad
// input exits with status 2 leaving nothing behind.
#include "harness/formats/tum_io.hpp"
#include "test_scenario_files.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <sys/wait.h>

namespace fs = std::filesystem;
using sonomap::test::input_error_of;
using sonomap::test::ScratchDir;

namespace {

// Camera 1.25 m above the floor of a 4 x 4 x 2.5 m room centred on the origin, looking along
// +x at the wall x = 2 and walking toward it at 0.9 m/s: at frame i (t = i/30 s) the wall is
// 2 - 0.03 i metres ahead. The file asks for Kinect noise; the tests override it to none.
const std::string kWallScene =
    "name: wall\n"
    "frames: 30\n"
    "sensor:\n"
    "  width: 64\n"
    "  height: 48\n"
    "  intrinsics: {fx: 52.5, fy: 52.5, cx: 31.5, cy: 23.5}\n"
    "  noise: {model: kinect}\n"
    "body:\n"
    "  interpolation: linear_slerp\n"
    "  keyframes:\n"
    "    - {time: 0, position: [0, 0, 1.25]}\n"
    "    - {time: 1, position: [0.9, 0, 1.25]}\n"
    "static:\n"
    "  - name: room\n"
    "    room: {size: [4, 4, 2.5]}\n";

double wall_distance(int frame) { return 2.0 - 0.03 * frame; }

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// Runs the sonomap executable (SONOMAP_EXE, set by ctest); returns its exit status.
int run_sonomap(const std::string& arguments, const fs::path& log) {
  const char* exe = std::getenv("SONOMAP_EXE");
  if (!exe) FAIL("SONOMAP_EXE is not set: run this test under ctest");
  const std::string command = "'" + std::string(exe) + "' " + arguments + " > " + quoted(log) + " 2>&1";
  const int status = std::system(command.c_str());
  REQUIRE(WIFEXITED(status));
  return WEXITSTATUS(status);
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Nothing named like the output (no partial directory either) exists in its parent.
bool nothing_written(const fs::path& out) {
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    if (entry.path().filename().string().rfind(out.filename().string(), 0) == 0) return false;
  return true;
}

}  // namespace

TEST_CASE("render writes depth PNGs holding the wall distance and the true camera poses",
          "[render]") {
  ScratchDir dir("render");
  const fs::path scene = dir.write("wall.yaml", kWallScene);
  const fs::path out = dir.path() / "seq";
  const int frames = 4;
  REQUIRE(run_sonomap("-q render " + quoted(scene) + " --out " + quoted(out) + " --frames " +
                          std::to_string(frames) + " --set sensor.noise.model=none --set seed=3",
                      dir.path() / "log.txt") == 0);

  const auto sequence = sonomap::harness::read_tum_sequence(out);
  REQUIRE(sequence.frames.size() == static_cast<std::size_t>(frames));
  CHECK(sequence.frames_without_pose == 0);
  const auto& camera = sequence.camera.camera;
  CHECK(camera.width == 64);
  CHECK(camera.fx == 52.5);
  CHECK(camera.cy == 23.5);
  CHECK(sequence.camera.depth_scale == 5000.0);
  CHECK(sequence.camera.name == "wall");
  CHECK(camera.body_T_camera.isApprox(sonomap::sim::CameraSpec::default_body_T_camera(), 1e-12));

  for (int i = 0; i < frames; ++i) {
    INFO("frame " << i);
    const auto& info = sequence.frames[i];
    CHECK(info.timestamp == Approx(i / 30.0).margin(1e-6));
    // The PNG itself: the pixels next to the principal point (31.5, 23.5) see the wall
    // face-on, so their z-depth is the wall distance, to within the PNG's 1/5000 m.
    const auto png = sonomap::harness::read_png16(info.depth_file);
    REQUIRE(png.width == 64);
    REQUIRE(png.height == 48);
    for (const auto& [u, v] : {std::pair{31, 23}, std::pair{32, 24}}) {
      const double z = png.pixels[static_cast<std::size_t>(v) * 64 + u] / 5000.0;
      CHECK(std::abs(z - wall_distance(i)) <= 1.0 / 5000.0 + 1e-9);
    }
    // groundtruth.txt: the camera at (0.03 i, 0, 1.25) looking along +x (optical z = world x).
    CHECK(info.world_T_camera.translation().isApprox(Eigen::Vector3d(0.03 * i, 0, 1.25), 1e-8));
    CHECK(info.world_T_camera.linear().col(2).isApprox(Eigen::Vector3d::UnitX(), 1e-8));
    CHECK(info.world_T_camera.linear().col(0).isApprox(-Eigen::Vector3d::UnitY(), 1e-8));

    // The reader's frame: depth in metres, points back-projected, body pose under the camera.
    const auto frame = sonomap::harness::load_tum_frame(sequence, i);
    CHECK(frame.time == Approx(i / 30.0).margin(1e-6));
    CHECK(std::abs(frame.depth[23 * 64 + 31] - wall_distance(i)) <= 1.0 / 5000.0 + 1e-6);
    std::size_t valid = 0;
    for (float z : frame.depth) valid += z > 0.0f;
    CHECK(frame.points_camera.size() == valid);
    CHECK(valid == frame.depth.size());  // a closed room: every pixel sees a surface
    CHECK(frame.world_T_body.translation().isApprox(Eigen::Vector3d(0.03 * i, 0, 1.25), 1e-8));
    CHECK(frame.world_T_body.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-8));
  }
  // The files follow the TUM layout.
  const std::string depth_list = text_of(out / "depth.txt");
  CHECK(depth_list.rfind("# depth maps\n", 0) == 0);
  CHECK(depth_list.find("\n0.033333 depth/0.033333.png\n") != std::string::npos);
  CHECK(text_of(out / "groundtruth.txt").find("# timestamp tx ty tz qx qy qz qw\n") !=
        std::string::npos);
}

TEST_CASE("render: bad input exits with status 2 and writes nothing", "[render][bad-input]") {
  ScratchDir dir("render");
  const fs::path out = dir.path() / "seq";
  const fs::path log = dir.path() / "log.txt";
  const auto render = [&](const fs::path& scene, const std::string& extra = "") {
    return run_sonomap("render " + quoted(scene) + " --out " + quoted(out) + " " + extra, log);
  };

  SECTION("zero focal length") {
    std::string text = kWallScene;
    text.replace(text.find("fx: 52.5"), 8, "fx: 0");
    CHECK(render(dir.write("bad.yaml", text)) == 2);
    const std::string message = text_of(log);
    INFO(message);
    CHECK(message.find("bad.yaml:6:") != std::string::npos);
    CHECK(message.find("'sensor.intrinsics.fx'") != std::string::npos);
  }
  SECTION("malformed YAML") {
    CHECK(render(dir.write("bad.yaml", kWallScene + "static: [\n")) == 2);
    CHECK(text_of(log).find("bad.yaml:") != std::string::npos);
  }
  SECTION("unknown key in an override") {
    CHECK(render(dir.write("wall.yaml", kWallScene), "--set sensor.nosie.model=none") == 2);
    CHECK(text_of(log).find("sensor.nosie") != std::string::npos);
  }
  SECTION("missing scenario file") {
    CHECK(render(dir.path() / "absent.yaml") == 2);
    CHECK(text_of(log).find("absent.yaml") != std::string::npos);
  }
  CHECK(nothing_written(out));
}

TEST_CASE("render never replaces a directory that is not a sequence", "[render][bad-input]") {
  ScratchDir dir("render");
  const fs::path scene = dir.write("wall.yaml", kWallScene);
  const fs::path keep = dir.write("precious/notes.txt", "mine");
  CHECK(run_sonomap("render " + quoted(scene) + " --out " + quoted(keep.parent_path()) +
                        " --frames 1",
                    dir.path() / "log.txt") == 2);
  CHECK(text_of(keep) == "mine");
}

TEST_CASE("16-bit PNGs round-trip every value, other files are clear errors", "[render]") {
  ScratchDir dir("render");
  sonomap::harness::DepthImage16 image;
  image.width = 300;
  image.height = 3;
  for (int i = 0; i < image.width * image.height; ++i)
    image.pixels.push_back(static_cast<std::uint16_t>((i * 7919) % 65536));
  image.pixels[0] = 0;
  image.pixels[1] = 65535;
  const fs::path file = dir.path() / "d.png";
  sonomap::harness::write_png16(file, image);
  const auto back = sonomap::harness::read_png16(file);
  CHECK(back.width == 300);
  CHECK(back.height == 3);
  CHECK(back.pixels == image.pixels);

  const fs::path junk = dir.write("junk.png", "not a png at all");
  CHECK(input_error_of([&] { sonomap::harness::read_png16(junk); }).find("junk.png") !=
        std::string::npos);
  CHECK(input_error_of([&] { sonomap::harness::read_png16(dir.path() / "none.png"); })
            .find("none.png") != std::string::npos);
}

TEST_CASE("reading a sequence: malformed lines name the file and line", "[render][bad-input]") {
  ScratchDir dir("render");
  dir.write("seq/camera.yaml", "width: 4\nheight: 2\nintrinsics: {fx: 3, fy: 3, cx: 1.5, cy: 0.5}\n");
  dir.write("seq/depth.txt", "# depth maps\n0.0 depth/0.png\n0.5 depth/1.png\n");
  const auto reading_error = [&] {
    return input_error_of([&] { sonomap::harness::read_tum_sequence(dir.path() / "seq"); });
  };
  SECTION("a ground-truth line with 7 numbers") {
    dir.write("seq/groundtruth.txt", "# gt\n0.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 1\n");
    const std::string message = reading_error();
    CHECK(message.find("groundtruth.txt:3:") != std::string::npos);
    CHECK(message.find("found 7 fields") != std::string::npos);
  }
  SECTION("a field that is not a number is named, with its text") {
    struct Case {
      const char* file;
      const char* text;
      const char* where;
      const char* field;
    };
    for (const Case& bad : {Case{"seq/groundtruth.txt", "0.0 0 0 0 0 0 0 1\n0.5 0 0 0 nan 0 0 1\n",
                                 "groundtruth.txt:2:", "'qx': 'nan' is not a finite number"},
                            Case{"seq/depth.txt", "# depth maps\n0.0 depth/0.png\n0,5 depth/1.png\n", "depth.txt:3:",
                                 "'timestamp': '0,5' is not a finite number"}}) {
      INFO(bad.file);
      dir.write("seq/groundtruth.txt", "0.0 0 0 0 0 0 0 1\n");
      dir.write("seq/depth.txt", "# depth maps\n0.0 depth/0.png\n");
      dir.write(bad.file, bad.text);
      const std::string message = reading_error();
      CHECK(message.find(bad.where) != std::string::npos);
      CHECK(message.find(bad.field) != std::string::npos);
    }
  }
  SECTION("frames without a pose close in time are left out") {
    dir.write("seq/groundtruth.txt", "0.001 1 2 3 0 0 0 1\n");
    const auto sequence = sonomap::harness::read_tum_sequence(dir.path() / "seq");
    REQUIRE(sequence.frames.size() == 1);
    CHECK(sequence.frames_without_pose == 1);
    CHECK(sequence.frames[0].world_T_camera.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  }
  SECTION("an unknown key in camera.yaml") {
    dir.write("seq/groundtruth.txt", "0.0 0 0 0 0 0 0 1\n");
    dir.write("seq/camera.yaml", "width: 4\nheight: 2\nfocal: 3\n");
    const std::string message = reading_error();
    CHECK(message.find("camera.yaml:3:") != std::string::npos);
    CHECK(message.find("'focal'") != std::string::npos);
  }
}
