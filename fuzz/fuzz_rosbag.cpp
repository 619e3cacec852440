// SPDX-License-Identifier: GPL-3.0-or-later
// The ROS1 bag reader (`sonomap run SEQUENCE.yaml` with source: ros1_bag): the input is the
// bag. Its topics are listed (`rosbag info`), then it is read as a 16UC1 image topic with a
// camera_info topic and TransformStamped poses, and as a PointCloud2 topic with the camera
// given: up to four frames each, every frame's depth and pose touched.
#include "fuzz_support.hpp"
#include "harness/formats/rosbag_io.hpp"
#include "harness/support/errors.hpp"

#include <algorithm>
#include <string>

namespace {

sonomap::harness::SequenceSpec spec_of(const std::filesystem::path& bag, bool cloud) {
  sonomap::harness::SequenceSpec spec;
  spec.source = sonomap::harness::SequenceSource::Ros1Bag;
  spec.path = bag;
  spec.file = bag;
  spec.pose_format = sonomap::harness::PoseFormat::Topic;
  spec.pose_topic = "/pose";
  if (cloud) {
    spec.encoding = sonomap::harness::DepthEncoding::PointCloud2;
    spec.depth_topic = "/points";
    spec.camera.width = 4, spec.camera.height = 3, spec.camera.fx = spec.camera.fy = 3.0;
    spec.camera.cx = 1.5, spec.camera.cy = 1.0;
  } else {
    spec.encoding = sonomap::harness::DepthEncoding::Mono16;
    spec.depth_scale = 1000.0;
    spec.depth_topic = "/depth";
    spec.camera_info_topic = "/camera_info";
  }
  return spec;
}

// Reads the first frames; a pixel sum keeps the reads from being optimised away.
void read_frames(const sonomap::harness::SequenceSpec& spec) {
  const auto reader = sonomap::harness::open_rosbag_reader(spec);
  double sum = 0.0;
  for (int i = 0; i < std::min(reader->count(), 4); ++i) {
    const sonomap::harness::DepthRecord record = reader->read(i);
    for (const double d : record.depth) sum += d;
    for (const auto& p : record.points) sum += p.sum();
    sum += record.world_T_camera.translation().sum();
  }
  static volatile double sink;
  sink = sum;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonomap;
  const std::filesystem::path bag =
      fuzz::write_file("in.bag", std::string(reinterpret_cast<const char*>(data), size));
  try {
    harness::list_rosbag_topics(bag);
  } catch (const harness::InputError&) {
  }
  for (const bool cloud : {false, true}) {
    try {
      read_frames(spec_of(bag, cloud));
    } catch (const harness::InputError&) {
    }
  }
  return 0;
}
