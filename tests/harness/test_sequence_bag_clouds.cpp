// SPDX-License-Identifier: GPL-3.0-or-later
// Bags whose depth is a sensor_msgs/PointCloud2 (as the Cow and Lady bag has it): an organised
// cloud gives the same circle as the depth image it came from, an unorganised one the same from
// its points alone (Open3D's map the same from an organised cloud as from its image), and a
// mapper that fuses depth images refuses unorganised clouds clearly.
// Reading a 3000-message bag streams: the process's peak memory does not grow with the bag.
#include "score_support.hpp"
#include "test_sequence_support.hpp"

#include "harness/formats/rosbag_io.hpp"
#include "harness/formats/sequence_io.hpp"
#include "../skip.hpp"

#include <sys/resource.h>

#include <fstream>

namespace fs = std::filesystem;
using namespace sonomap;

namespace {

constexpr double kStart = 100.0;

// 16 x 12 pixels, 90 degrees across: a wall 2 m ahead fills the image.
sim::CameraSpec tiny_camera() {
  sim::CameraSpec camera;
  camera.width = 16, camera.height = 12, camera.fx = camera.fy = 8.0, camera.cx = 7.5, camera.cy = 5.5;
  return camera;
}

// Two frames of the wall as an image, an organised and an unorganised cloud (with `holes`, a
// quarter of the pixels with no return), with camera_info and the poses.
fs::path wall_bag(const fs::path& dir, const sim::CameraSpec& camera = tiny_camera(), bool holes = true) {
  std::vector<float> depth(static_cast<std::size_t>(camera.width) * camera.height, 2.0f);
  if (holes)
    for (std::size_t k = 0; k < depth.size(); k += 4) depth[k] = 0.0f;
  const fs::path file = dir / "wall.bag";
  const auto bag = harness::open_rosbag_writer(file);
  for (int i = 0; i < 2; ++i) {
    bag->camera_info("/camera/info", kStart + i, "camera", camera);
    bag->depth("/camera/image", kStart + i, "camera", camera.width, camera.height, depth);
    bag->point_cloud("/camera/organised", kStart + i, "camera", camera, depth, true);
    bag->point_cloud("/camera/unorganised", kStart + i, "camera", camera, depth, false);
    // The camera level at the origin, looking along +x (the default mount on a body there).
    bag->transform("/pose", kStart + i, "world", "camera", sim::CameraSpec::default_body_T_camera());
  }
  bag->close();
  return file;
}

void write_sequence(const fs::path& file, const std::string& topic, const std::string& encoding,
                    const std::string& camera = "info_topic: /camera/info") {
  std::ofstream(file) << "sequence:\n"
                         "  source: ros1_bag\n"
                         "  path: wall.bag\n"
                         "  depth: {topic: " << topic << ", encoding: " << encoding << "}\n"
                         "  camera: {" << camera << "}\n"
                         "  poses: {format: topic, topic: /pose}\n"
                         "  world: {floor: -1.5}\n";
}

long peak_rss_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

}  // namespace

TEST_CASE("PointCloud2 depth: organised like its image, unorganised from its points", "[sequence][rosbag]") {
  test::ScratchDir scratch("sequence-bag-clouds");
  wall_bag(scratch.path());
  const fs::path image = scratch.path() / "image.yaml", organised = scratch.path() / "organised.yaml",
                 unorganised = scratch.path() / "unorganised.yaml";
  write_sequence(image, "/camera/image", "32FC1");
  write_sequence(organised, "/camera/organised", "PointCloud2");
  write_sequence(unorganised, "/camera/unorganised", "PointCloud2");
  test::run_quietly(image, scratch.path() / "run-image");
  test::run_quietly(organised, scratch.path() / "run-organised");
  test::run_quietly(unorganised, scratch.path() / "run-unorganised");
  const auto from_image = test::circle_of(scratch.path() / "run-image/circle.csv", 1);
  // The wall covers the 90 degrees ahead at 2 m; its 16 pixel columns (6 degrees apart) fall in
  // at least 12 bins. Same bins, same values to the last digit.
  CHECK(test::compare_circles(from_image, test::circle_of(scratch.path() / "run-organised/circle.csv", 1), 0.0) >= 12);
  CHECK(test::compare_circles(from_image, test::circle_of(scratch.path() / "run-unorganised/circle.csv", 1), 0.0) >= 12);

  SECTION("a mapper that fuses depth images refuses an unorganised cloud") {
    const auto result = test::run_sonomap({"--quiet", "run", unorganised.string(), "--mapper", "open3d", "--out",
                                           (scratch.path() / "open3d").string()});
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("unorganised point clouds"));
    CHECK_THAT(result.output, Catch::Contains("mapper open3d fuses depth images"));
    CHECK(test::nothing_written(scratch.path() / "open3d"));
  }
  SECTION("an organised cloud of another size than the camera names the message") {
    write_sequence(organised, "/camera/organised", "PointCloud2",
                   "width: 8, height: 6, intrinsics: {fx: 4, fy: 4, cx: 3.5, cy: 2.5}");
    const auto result = test::run_sonomap({"--quiet", "run", organised.string(), "--out", (scratch.path() / "bad").string()});
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("topic /camera/organised, message 0: organised cloud is 16x12, the camera 8x6"));
  }
  SECTION("an image topic read as a cloud names the type") {
    write_sequence(organised, "/camera/image", "PointCloud2");
    const auto result = test::run_sonomap({"--quiet", "run", organised.string(), "--out", (scratch.path() / "bad").string()});
    CHECK(result.status == 2);
    CHECK_THAT(result.output, Catch::Contains("sensor_msgs/Image; expected sensor_msgs/PointCloud2"));
  }
}

// As scenes/cow_and_lady_paper.yaml has it: the bag holds organised clouds only. A map needs more
// than the tiny camera's pixels, 25 cm apart on the wall: 160 x 120 puts them 2.5 cm apart. Every
// pixel returns: with the holes (every 4th pixel, so columns 10 cm apart on the wall) neither
// TSDF, Open3D's or ours, made any surface of it, as a projective TSDF fuses a voxel only where
// its centre's pixel returned and marching cubes needs whole cubes.
TEST_CASE("Open3D fuses an organised cloud as the depth image it came from", "[sequence][rosbag]") {
  test::ScratchDir scratch("sequence-bag-open3d");
  sim::CameraSpec camera = tiny_camera();
  camera.width = 160, camera.height = 120, camera.fx = camera.fy = 80.0, camera.cx = 79.5, camera.cy = 59.5;
  wall_bag(scratch.path(), camera, false);
  const fs::path image = scratch.path() / "image.yaml", organised = scratch.path() / "organised.yaml";
  write_sequence(image, "/camera/image", "32FC1");
  write_sequence(organised, "/camera/organised", "PointCloud2");
  test::run_quietly(image, scratch.path() / "run-image", {}, "open3d");
  test::run_quietly(organised, scratch.path() / "run-organised", {}, "open3d");
  const auto from_image = test::circle_of(scratch.path() / "run-image/circle.csv", 1);
  const auto from_cloud = test::circle_of(scratch.path() / "run-organised/circle.csv", 1);
  test::compare_circles(from_image, from_cloud, 0.0);
  // The wall 2 m ahead fills the 90 degrees ahead: the bins within 40 degrees of straight ahead
  // read its range at the bin's nearer edge (a square room's wall ahead: square_room_truth),
  // within 5 cm.
  for (int bin = -40; bin <= 40; ++bin) {
    const int k = (bin + 360) % 360;
    const std::string& estimate = from_cloud.at(k);
    INFO("bin " << bin);
    REQUIRE(!estimate.empty());
    CHECK(std::stod(estimate) == Approx(test::square_room_truth(k)).margin(0.05));
  }
}

TEST_CASE("reading a 3000-message bag keeps memory flat", "[sequence][rosbag]") {
#if defined(__SANITIZE_ADDRESS__)
  SONOMAP_SKIP("AddressSanitizer keeps freed memory in quarantine: peak RSS says nothing here");
#endif
  test::ScratchDir scratch("sequence-bag-memory");
  const int messages = 3000;
  sim::CameraSpec camera;
  camera.width = 64, camera.height = 48, camera.fx = camera.fy = 50.0, camera.cx = 31.5, camera.cy = 23.5;
  {
    const auto bag = harness::open_rosbag_writer(scratch.path() / "long.bag");
    std::vector<float> depth(64 * 48, 2.0f);
    for (int i = 0; i < messages; ++i) {
      const double stamp = kStart + i / 30.0;
      bag->depth("/depth", stamp, "camera", 64, 48, depth, 1000.0);  // 16UC1 millimetres
      bag->transform("/pose", stamp, "world", "camera", Eigen::Isometry3d::Identity());
    }
    bag->close();
  }
  std::ofstream(scratch.path() / "long.yaml")
      << "sequence:\n  source: ros1_bag\n  path: long.bag\n  depth: {topic: /depth, encoding: 16UC1, scale: 1000}\n"
         "  camera: {width: 64, height: 48, intrinsics: {fx: 50, fy: 50, cx: 31.5, cy: 23.5}}\n"
         "  poses: {format: topic, topic: /pose}\n";
  auto sequence = harness::open_recorded_sequence(scratch.path() / "long.yaml");
  REQUIRE(sequence->frame_count() == messages);
  const auto read = [&](int from, int to) {
    std::size_t points = 0;
    for (int i = from; i < to; ++i) points += sequence->frame(i).points_camera.size();
    return points;
  };
  CHECK(read(0, messages / 2) == static_cast<std::size_t>(messages / 2) * 64 * 48);
  const long half = peak_rss_kib();
  CHECK(read(messages / 2, messages) == static_cast<std::size_t>(messages / 2) * 64 * 48);
  const long all = peak_rss_kib();
  // Each half of the bag holds 1500 x 6 KiB = 9 MiB of depth: loading it would show. Streaming
  // leaves the peak where one frame (a few hundred KiB with its points) put it.
  const long half_bag_kib = static_cast<long>(fs::file_size(scratch.path() / "long.bag") / 2 / 1024);
  UNSCOPED_INFO("peak RSS after half the bag " << half << " KiB, after all " << all << " KiB; half the bag is "
                << half_bag_kib << " KiB");
  CHECK(all - half < half_bag_kib / 8);
}

TEST_CASE("scenes/cow_and_lady.yaml parses and, without the bag, names the missing bag", "[sequence][rosbag]") {
  const fs::path file = test::shipped("scenes/cow_and_lady.yaml");
  const fs::path bag = file.parent_path() / "cow_and_lady/data.bag";
  const harness::SequenceSpec spec = harness::load_sequence_spec(file);
  CHECK(spec.source == harness::SequenceSource::Ros1Bag);
  CHECK(spec.path == bag);
  CHECK(spec.depth_topic == "/camera/depth_registered/points");
  CHECK(spec.encoding == harness::DepthEncoding::PointCloud2);
  CHECK(spec.pose_topic == "/kinect/vrpn_client/estimated_transform");
  CHECK(spec.pose_T_camera.translation().y() == Approx(0.0450936));
  CHECK(spec.truth_file.filename() == "cow_and_lady_gt.ply");
  if (fs::exists(bag)) SONOMAP_SKIP("the Cow and Lady bag is present at " << bag << ": not testing its absence");
  test::ScratchDir scratch("cow-and-lady");
  const auto result = test::run_sonomap({"--quiet", "run", file.string(), "--out", (scratch.path() / "out").string()});
  CHECK(result.status == 2);
  CHECK_THAT(result.output, Catch::Contains(bag.string() + ": missing or not a regular file"));
  CHECK(test::nothing_written(scratch.path() / "out"));
}
