// SPDX-License-Identifier: GPL-3.0-or-later
// ROS1 bags in: the smoke scene written as a bag (32FC1 depth, camera_info, the body's pose as a
// TransformStamped, like a tracking marker) runs from a sequence file and gives the direct
// run's circle within float32 rounding. Bad bags (truncated, a missing topic, a wrong message
// type, stamps out of order) exit 2 naming the topic and the message.
#include "test_sequence_support.hpp"

#include "harness/formats/rosbag_io.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "sim/simulation.hpp"

#include <fstream>

namespace fs = std::filesystem;
using namespace sonomap;

namespace {

constexpr double kStart = 100.0;  // bag stamps must be positive

std::string sequence_text(const fs::path& bag, const std::string& depth_topic, const Eigen::Isometry3d& mount) {
  return "sequence:\n"
         "  source: ros1_bag\n"
         "  path: " + bag.filename().string() + "\n"
         "  depth: {topic: " + depth_topic + ", encoding: 32FC1}\n"
         "  camera:\n"
         "    info_topic: /camera/depth/camera_info\n"
         "    body_T_camera: " + test::yaml_matrix(mount.matrix()) + "\n"
         "  poses:\n"
         "    format: topic\n"
         "    topic: /vicon/body\n"
         "    pose_T_camera: " + test::yaml_matrix(mount.matrix()) + "\n"
         "  time: {tolerance: 0.001}\n";
}

// A 4 x 3 bag whose depth topic holds `depth_messages` (stamp, record time) images at 2 m.
fs::path tiny_bag(const fs::path& dir, const std::vector<std::pair<double, double>>& depth_messages,
                  bool camera_info_as_depth = false) {
  const fs::path file = dir / "tiny.bag";
  sim::CameraSpec camera;
  camera.width = 4, camera.height = 3, camera.fx = camera.fy = 3.0, camera.cx = 1.5, camera.cy = 1.0;
  harness::RosbagWriter bag(file);
  bag.camera_info("/camera/depth/camera_info", kStart, "camera", camera);
  if (camera_info_as_depth) bag.camera_info("/camera/depth/image", kStart, "camera", camera);
  for (const auto& [stamp, received] : depth_messages)
    bag.depth("/camera/depth/image", stamp, "camera", 4, 3, std::vector<float>(12, 2.0f), 0.0, received);
  for (int i = 0; i < 5; ++i) bag.transform("/vicon/body", kStart + i, "world", "body", Eigen::Isometry3d::Identity());
  bag.close();
  return file;
}

test::CliResult run_cli(const fs::path& sequence, const fs::path& out) {
  return test::run_sonomap({"--quiet", "run", sequence.string(), "--out", out.string()});
}

}  // namespace

// `sonomap render --format rosbag` of the smoke scene at the small camera, 6 frames, into `out`.
void render_smoke_bag(const fs::path& out) {
  std::vector<std::string> render = {"--quiet", "render", test::shipped("scenes/smoke.yaml").string(), "--format",
                                     "rosbag", "--out", out.string(), "--frames", "6", "--truth-spacing", "0.05"};
  for (const auto& key : test::small_camera_keys()) render.insert(render.end(), {"--set", key});
  const auto result = test::run_sonomap(render);
  INFO(result.output);
  REQUIRE(result.status == 0);
}

double metric(const nlohmann::json& summary, const std::string& name) {
  return summary["metrics"]["circle"]["mean"][name].get<double>();
}

TEST_CASE("a scenario rendered as a ROS1 bag runs from its sequence file like the scenario",
          "[sequence][rosbag]") {
  test::ScratchDir scratch("sequence-rosbag");
  render_smoke_bag(scratch.path() / "bag");
  // The Cow and Lady topic layout, one message per frame on each topic.
  std::map<std::string, std::string> types;
  for (const auto& t : harness::list_rosbag_topics(scratch.path() / "bag/data.bag")) {
    types[t.topic] = t.type;
    CHECK(t.messages == 6);
  }
  CHECK(types["/camera/depth_registered/points"] == "sensor_msgs/PointCloud2");
  CHECK(types["/kinect/vrpn_client/estimated_transform"] == "geometry_msgs/TransformStamped");
  CHECK(types["/camera/depth_registered/image"] == "sensor_msgs/Image");
  CHECK(types["/camera/depth_registered/camera_info"] == "sensor_msgs/CameraInfo");
  CHECK(types["/tf"] == "tf2_msgs/TFMessage");

  const auto direct = test::run_quietly(test::shipped("scenes/smoke.yaml"), scratch.path() / "direct",
                                        test::small_camera_keys());
  const auto bagged = test::run_quietly(scratch.path() / "bag/sequence.yaml", scratch.path() / "bagged");
  CHECK(bagged["ground_truth"] == true);  // truth.ply beside the bag
  // The cloud holds the simulator's float32 depths as z; the points are recomputed from them,
  // so each coordinate (|p| <= 5 m x 1.255 along the corner rays) moves by float32 rounding
  // only: 6.3 m x 2^-24 = 0.4 um, a few times over in the chain's float arithmetic.
  const int known = test::compare_circles(test::circle_of(scratch.path() / "direct/circle.csv", 5),
                                          test::circle_of(scratch.path() / "bagged/circle.csv", 5), 2e-6);
  CHECK(known > 40);
  // Against the reference cloud (covering radius <= 0.05 m) the metrics are those of the exact
  // truth up to that radius, where the cells are wide enough (eval/cloud_truth.hpp); printed
  // for the record, the bound itself is tested in tests/eval/test_cloud_truth.cpp.
  UNSCOPED_INFO("circle RMSE direct " << metric(direct, "rmse") << " bag " << metric(bagged, "rmse")
                << "; coverage direct " << metric(direct, "coverage") << " bag "
                << metric(bagged, "coverage"));
  CHECK(std::abs(metric(direct, "coverage") - metric(bagged, "coverage")) < 0.1);
}

TEST_CASE("render --format rosbag follows the output rules", "[sequence][rosbag]") {
  test::ScratchDir scratch("sequence-rosbag-out");
  const fs::path out = scratch.path() / "mine";
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "user data\n";
  const auto result = test::run_sonomap({"--quiet", "render", test::shipped("scenes/smoke.yaml").string(), "--format",
                                         "rosbag", "--out", out.string(), "--frames", "1"});
  CHECK(result.status == 2);
  CHECK(test::text_of(out / "notes.txt") == "user data\n");
  CHECK_FALSE(fs::exists(out / "data.bag"));
  render_smoke_bag(scratch.path() / "bag");
  render_smoke_bag(scratch.path() / "bag");  // an earlier render is replaced
  CHECK(fs::exists(scratch.path() / "bag/truth.ply"));
}

TEST_CASE("bad ROS1 bags fail naming the topic and the message", "[sequence][rosbag]") {
  test::ScratchDir scratch("sequence-rosbag-bad");
  const fs::path sequence = scratch.path() / "sequence.yaml";
  const fs::path out = scratch.path() / "out";
  const Eigen::Isometry3d mount = sim::CameraSpec::default_body_T_camera();
  const auto write_sequence = [&](const std::string& depth_topic) {
    std::ofstream(sequence) << sequence_text(scratch.path() / "tiny.bag", depth_topic, mount);
  };
  write_sequence("/camera/depth/image");

  SECTION("a good tiny bag runs") {
    tiny_bag(scratch.path(), {{kStart, 0.0}, {kStart + 1, 0.0}});
    CHECK(run_cli(sequence, out).status == 0);
    fs::remove_all(out);
  }
  SECTION("truncated") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}, {kStart + 1, 0.0}});
    fs::resize_file(bag, fs::file_size(bag) / 2);
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("tiny.bag"));
    CHECK_THAT(result.output, Catch::Contains("cannot read the ROS1 bag"));
  }
  SECTION("a missing topic") {
    tiny_bag(scratch.path(), {{kStart, 0.0}});
    write_sequence("/camera/depth/nope");
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("topic /camera/depth/nope: no such topic"));
  }
  SECTION("a wrong message type") {
    tiny_bag(scratch.path(), {}, /*camera_info_as_depth=*/true);
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("topic /camera/depth/image, message 0: message 0 is a sensor_msgs/CameraInfo"));
  }
  SECTION("header stamps out of order") {
    tiny_bag(scratch.path(), {{kStart + 2, kStart + 1}, {kStart + 1, kStart + 2}});
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("topic /camera/depth/image, message 1"));
    CHECK_THAT(result.output, Catch::Contains("stamps must be in order"));
  }
  CHECK(test::nothing_written(out));
}
