// SPDX-License-Identifier: GPL-3.0-or-later
// ROS1 bags in: the smoke scene written as a bag (32FC1 depth, camera_info, the body's pose as a
// TransformStamped, like a tracking marker) runs from a sequence file and gives the direct
// run's circle within float32 rounding. Bad bags (truncated, a corrupt length, a missing topic,
// a wrong message type, stamps out of order) exit 2 naming the place: the record's byte, or the
// topic and the message.
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
                  bool camera_info_as_depth = false,
                  harness::BagCompression compression = harness::BagCompression::None) {
  const fs::path file = dir / "tiny.bag";
  sim::CameraSpec camera;
  camera.width = 4, camera.height = 3, camera.fx = camera.fy = 3.0, camera.cx = 1.5, camera.cy = 1.0;
  const auto bag = harness::open_rosbag_writer(file, compression);
  bag->camera_info("/camera/depth/camera_info", kStart, "camera", camera);
  if (camera_info_as_depth) bag->camera_info("/camera/depth/image", kStart, "camera", camera);
  for (const auto& [stamp, received] : depth_messages)
    bag->depth("/camera/depth/image", stamp, "camera", 4, 3, std::vector<float>(12, 2.0f), 0.0, received);
  for (int i = 0; i < 5; ++i) bag->transform("/vicon/body", kStart + i, "world", "body", Eigen::Isometry3d::Identity());
  bag->close();
  return file;
}

// Writes `value` little-endian at byte `at` of `file` (a length field of the bag format).
void overwrite_u32(const fs::path& file, size_t at, std::uint32_t value) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(at));
  for (int i = 0; i < 4; ++i) f.put(static_cast<char>((value >> (8 * i)) & 0xFF));
  REQUIRE(f.good());
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

std::uint32_t u32_at(const std::string& bytes, size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
  return v;
}

// The top-level records of a bag (format 2.0: header length, header, data length, data), by
// the format's description: where each starts, its op code and where its data are.
struct BagRecord {
  size_t at = 0, data_at = 0, data_length = 0;
  char op = 0;
};
std::vector<BagRecord> bag_records(const std::string& bytes) {
  std::vector<BagRecord> records;
  for (size_t at = bytes.find('\n') + 1; at + 8 <= bytes.size();) {
    BagRecord r;
    r.at = at;
    const size_t header_length = u32_at(bytes, at);
    const size_t op = bytes.find(std::string("op=", 3), at + 4);
    REQUIRE(op < at + 4 + header_length);
    r.op = bytes[op + 3];
    r.data_at = at + 8 + header_length;
    r.data_length = u32_at(bytes, at + 4 + header_length);
    records.push_back(r);
    at = r.data_at + r.data_length;
  }
  return records;
}

BagRecord first_record(const fs::path& bag, char op) {
  for (const BagRecord& r : bag_records(test::text_of(bag)))
    if (r.op == op) return r;
  FAIL("no record of op " << int(op));
  return {};
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
  // The run exits 2 naming the record at byte `at` of the bag and what is wrong with it.
  const auto expect_record_refused = [&](size_t at, const std::string& what) {
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("the record at byte " + std::to_string(at) + " " + what));
  };

  SECTION("a good tiny bag runs, its chunks compressed or not") {
    const auto compression = GENERATE(harness::BagCompression::None, harness::BagCompression::Lz4,
                                      harness::BagCompression::Bz2);
    tiny_bag(scratch.path(), {{kStart, 0.0}, {kStart + 1, 0.0}}, false, compression);
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
  // rosbag and ROS's deserialiser size their buffers by a length field before reading: a
  // corrupt length must be an error naming the place, not gigabytes asked for.
  SECTION("a record claiming a header longer than the file") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    overwrite_u32(bag, 13, 0xFFFFFFF0u);  // the first record, after "#ROSBAG V2.0\n"
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("cannot read the ROS1 bag") &&
                                  Catch::Contains("the record at byte 13 claims a 4294967280-byte header"));
  }
  SECTION("a bag whose version line names another log type is read as a bag all the same") {
    // rosbag takes "#ROS<anything> V2.0" as version 2.0: so must the length checks.
    tiny_bag(scratch.path(), {{kStart, 0.0}});
    const fs::path bag = scratch.path() / "tiny.bag";
    const std::string bytes = test::text_of(bag);
    std::ofstream(bag, std::ios::binary | std::ios::trunc) << "#ROS_count=#ROSBAG" << bytes.substr(7);
    overwrite_u32(bag, 13 + 11, 0xFFFFFFF0u);  // the first record's header length
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("the record at byte 24 claims a 4294967280-byte header"));
  }
  // rosbag reads the version line with sscanf("#ROS%s V%d.%d"), whose %s skips white space
  // and takes a word of any length into 100 bytes, and counts the line to its first NUL.
  SECTION("a version line with white space before its log type is a bag, checked like any") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const std::string bytes = test::text_of(bag);
    std::ofstream(bag, std::ios::binary | std::ios::trunc) << "#ROS \tBAG V2.0\n" << bytes.substr(13);
    overwrite_u32(bag, 15, 0xFFFFFFF0u);  // the first record's header length
    expect_record_refused(15, "claims a 4294967280-byte header");
  }
  SECTION("a version line whose log type would overflow rosbag's buffer") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const std::string bytes = test::text_of(bag);
    std::ofstream(bag, std::ios::binary | std::ios::trunc) << "#ROS" << std::string(120, 'x') << " V2.0\n"
                                                           << bytes.substr(13);
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("tiny.bag") &&
                                  Catch::Contains("the version line's log type is 120 characters long"));
  }
  SECTION("a bag of the older format 1.2 is refused, not read unchecked") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const std::string bytes = test::text_of(bag);
    std::ofstream(bag, std::ios::binary | std::ios::trunc) << "#ROSRECORD V1.2\n" << bytes.substr(13);
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("tiny.bag") && Catch::Contains("bag format 1.2 is not read here"));
  }
  SECTION("a NUL in the version line: the records start there, as rosbag counts") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const std::string bytes = test::text_of(bag);
    std::ofstream(bag, std::ios::binary | std::ios::trunc) << bytes.substr(0, 12) << std::string(1, '\0')
                                                           << bytes.substr(12);
    // rosbag reads a record at byte 12: the NUL, the newline and the first record's length.
    expect_record_refused(12, "claims a " + std::to_string(0x0A00u | (u32_at(bytes, 13) << 16)) + "-byte header");
  }
  // Inside a chunk rosbag reads a record where an index entry points, trusting its lengths.
  SECTION("a record inside a chunk claiming a header past the chunk's end") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const BagRecord chunk = first_record(bag, '\x05');
    overwrite_u32(bag, chunk.data_at, static_cast<std::uint32_t>(chunk.data_length));  // its first record
    expect_record_refused(chunk.at, "is a chunk that holds, at byte 0 of its data, a record that claims a " +
                                        std::to_string(chunk.data_length) + "-byte header");
  }
  SECTION("an index entry pointing into the middle of a record") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const BagRecord index = first_record(bag, '\x04');
    overwrite_u32(bag, index.data_at + 8, 1);  // entry 0: sec, nsec, offset in the chunk
    expect_record_refused(index.at, "is an index whose entry 0 points at byte 1 of its chunk, where no message starts");
  }
  SECTION("a connection whose topic header has a field running past its end") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const BagRecord connection = first_record(bag, '\x07');  // the index's, after the chunk
    overwrite_u32(bag, connection.data_at, static_cast<std::uint32_t>(connection.data_length));
    expect_record_refused(connection.at,
                          "is a connection whose data (its topic's header) have a field running past their end");
  }
  SECTION("a chunk info naming a chunk where none starts") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}});
    const BagRecord info = first_record(bag, '\x06');
    const std::string bytes = test::text_of(bag);
    const size_t chunk_pos = bytes.find("chunk_pos=", info.at);
    REQUIRE(chunk_pos < info.data_at);
    overwrite_u32(bag, chunk_pos + 10, 14);  // one byte into the first record
    expect_record_refused(info.at, "names a chunk at byte 14, where none starts");
  }
  SECTION("a compressed chunk whose data do not uncompress") {
    const auto compression = GENERATE(harness::BagCompression::Lz4, harness::BagCompression::Bz2);
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}}, false, compression);
    const BagRecord chunk = first_record(bag, '\x05');
    overwrite_u32(bag, chunk.data_at + chunk.data_length / 2, 0xDEADBEEFu);
    expect_record_refused(chunk.at, "is a chunk whose data do not uncompress");
  }
  SECTION("an image whose pixel count runs past the message") {
    const fs::path bag = tiny_bag(scratch.path(), {{kStart, 0.0}, {kStart + 1, 0.0}});
    // sensor_msgs/Image: ..., encoding "32FC1", is_bigendian (1 byte), step (4), data count (4).
    const std::string bytes = test::text_of(bag);
    const size_t encoding = bytes.find("32FC1");
    REQUIRE(encoding != std::string::npos);
    overwrite_u32(bag, encoding + 5 + 1 + 4, 0x7FFFFFFFu);  // 2 GiB of pixels in a 48-byte array
    const auto result = run_cli(sequence, out);
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("topic /camera/depth/image, message 0") &&
                                  Catch::Contains("runs past its end"));
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
