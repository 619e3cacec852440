// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap render SCENARIO.yaml --out DIR [--format rosbag]`: the simulated depth frames as a
// TUM RGB-D sequence or a ROS1 bag with a reference cloud and the sequence file that runs it.
#include "harness/app/render_command.hpp"

#include "harness/app/cli.hpp"
#include "harness/app/frame_source.hpp"
#include "eval/cloud_truth.hpp"
#include "harness/formats/mesh_io.hpp"
#include "harness/formats/rosbag_io.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/tum_io.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"
#include "sim/simulation.hpp"
#include "sim/world_geometry.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <system_error>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

struct RenderOptions {
  std::string scenario;
  std::string out;
  std::string format = "tum";
  double truth_spacing = 0.02;
  int frames = 0;  // 0: the scenario's
  std::vector<std::string> overrides;
};

std::unique_ptr<sim::Simulation> simulation_of(const sim::Scenario& scenario, const fs::path& file) {
  try {
    return std::make_unique<sim::Simulation>(scenario);
  } catch (const std::invalid_argument& e) {
    throw InputError(file.string(), 0, "", e.what());
  }
}

// The Cow and Lady bag's topics (voxblox's cow_and_lady_dataset.launch) and frames; the depth
// image, camera_info and tf come with it so that nodes expecting either input can play it.
constexpr const char* kCloudTopic = "/camera/depth_registered/points";
constexpr const char* kImageTopic = "/camera/depth_registered/image";
constexpr const char* kInfoTopic = "/camera/depth_registered/camera_info";
constexpr const char* kPoseTopic = "/kinect/vrpn_client/estimated_transform";
constexpr const char* kWorldFrame = "world", *kMarkerFrame = "kinect", *kCameraFrame = "camera_rgb_optical_frame";
constexpr double kBagStart = 1000.0;  // bag stamps must be positive; fixed, so reruns are identical

// A 4x4 matrix as YAML rows, exactly (17 significant digits).
std::string yaml_matrix(const Eigen::Isometry3d& t) {
  std::string out = "[";
  for (int r = 0; r < 4; ++r)
    out += fmt::format("{}[{:.17g}, {:.17g}, {:.17g}, {:.17g}]", r ? ", " : "", t(r, 0), t(r, 1), t(r, 2), t(r, 3));
  return out + "]";
}

// The sequence file that runs the rendered bag: the pose topic is the listener's body (the
// tracking marker), so pose_T_camera is the camera's mount on the body.
std::string rendered_sequence_yaml(const sim::Scenario& scenario) {
  const sim::CameraSpec& c = scenario.camera;
  return fmt::format(
      "# Written by sonomap render --format rosbag: runs data.bag with truth.ply as ground truth.\n"
      "sequence:\n"
      "  name: {}\n"
      "  source: ros1_bag\n"
      "  path: data.bag\n"
      "  depth: {{topic: {}, encoding: PointCloud2}}\n"
      "  camera:\n"
      "    info_topic: {}\n"
      "    min_range: {:.17g}\n"
      "    max_range: {:.17g}\n"
      "    body_T_camera: {}\n"
      "  poses:\n"
      "    format: topic\n"
      "    topic: {}\n"
      "    pose_T_camera: {}\n"
      "  world: {{up: +z, floor: {:.17g}}}\n"
      "  time: {{tolerance: 0.001, match: nearest}}\n"
      "  truth: {{cloud: truth.ply}}\n",
      scenario.name, kCloudTopic, kInfoTopic, c.min_range, c.max_range, yaml_matrix(c.body_T_camera),
      kPoseTopic, yaml_matrix(c.body_T_camera), scenario.ground_z);
}

// One frame in the bag: the cloud, the image, camera_info, the pose the mapper was given (as a
// localiser would publish it) on the pose topic and as tf.
void write_bag_frame(RosbagWriter& bag, const sim::CameraSpec& camera, const Frame& frame) {
  const double stamp = kBagStart + frame.time;
  bag.point_cloud(kCloudTopic, stamp, kCameraFrame, camera, frame.depth);
  bag.depth(kImageTopic, stamp, kCameraFrame, frame.width, frame.height, frame.depth);
  bag.camera_info(kInfoTopic, stamp, kCameraFrame, camera);
  bag.transform(kPoseTopic, stamp, kWorldFrame, kMarkerFrame, frame.world_T_body);
  bag.tf("/tf", stamp, {{kWorldFrame, kMarkerFrame, frame.world_T_body},
                         {kMarkerFrame, kCameraFrame, camera.body_T_camera}});
}

// The static scene (moving objects left out: a reference cloud is one instant's scene).
std::vector<Eigen::Vector3f> static_truth_cloud(sim::Scenario scenario, double spacing) {
  scenario.movers.clear();
  return eval::surface_samples(sim::world_triangles(scenario, 0.0), spacing);
}

}  // namespace

void render_rosbag(const fs::path& scenario_file, const std::vector<std::string>& overrides,
                   const fs::path& out, double truth_spacing, bool quiet) {
  const sim::Scenario scenario = load_scenario(scenario_file, overrides);
  const std::unique_ptr<sim::Simulation> simulation = simulation_of(scenario, scenario_file);
  StagedDirectory staged(out, "render", scenario_inputs(scenario, scenario_file));
  const std::unique_ptr<RosbagWriter> bag = open_rosbag_writer(staged.path() / "data.bag");
  const int frames = simulation->frame_count();
  Progress progress("render", frames, quiet);
  for (int i = 0; i < frames; ++i) {
    throw_if_interrupted();
    write_bag_frame(*bag, scenario.camera, simulation->render(i));
    progress.update(i + 1);
  }
  bag->close();
  progress.finish();
  save_point_cloud_ply(staged.path() / "truth.ply", static_truth_cloud(scenario, truth_spacing));
  std::ofstream(staged.path() / "sequence.yaml") << rendered_sequence_yaml(scenario);
  staged.commit();
  if (!quiet)
    std::printf("render: %d frames of '%s' written to %s as a ROS1 bag (data.bag, truth.ply, sequence.yaml)\n",
                frames, scenario.name.c_str(), out.string().c_str());
}

void render_sequence(const fs::path& scenario_file, const std::vector<std::string>& overrides,
                     const fs::path& out, bool quiet) {
  const sim::Scenario scenario = load_scenario(scenario_file, overrides);

  CameraFile camera{scenario.name, scenario.camera, kTumDepthScale};
  if (camera.camera.max_range * camera.depth_scale > 65535.0)
    throw InputError(scenario_file.string(), 0, "sensor.max_range",
                     "a 16-bit PNG at " + std::to_string(static_cast<int>(kTumDepthScale)) +
                         " per metre holds depths up to " + std::to_string(65535.0 / kTumDepthScale) +
                         " m; lower max_range to render this scenario");

  const std::unique_ptr<sim::Simulation> simulation = simulation_of(scenario, scenario_file);

  StagedDirectory staged(out, "render", scenario_inputs(scenario, scenario_file));
  TumWriter writer(staged.path(), camera);
  const int frames = simulation->frame_count();
  Progress progress("render", frames, quiet);
  for (int i = 0; i < frames; ++i) {
    throw_if_interrupted();
    const Frame frame = simulation->render(i);
    writer.add(frame, simulation->true_camera_pose(frame.time));
    progress.update(i + 1);
  }
  writer.finish();
  progress.finish();
  staged.commit();
  if (!quiet)
    std::printf("render: %d frames of '%s' written to %s\n", frames, scenario.name.c_str(),
                out.string().c_str());
}

void add_render_command(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* command = app.add_subcommand(
      "render", "Render a scenario's depth frames as a TUM RGB-D sequence: depth/*.png (16-bit, "
                "5000 per metre, 0 = no return), depth.txt, groundtruth.txt (true camera pose), "
                "camera.yaml; or with --format rosbag as a ROS1 bag in the Cow and Lady layout: "
                "data.bag, truth.ply (reference cloud), sequence.yaml");
  command->add_option("scenario", options->scenario, "Scenario file (format: scenes/README.md)")
      ->required();
  command->add_option("--out", options->out,
                      "Output directory: written whole or not at all; new, empty, or an earlier "
                      "sonomap result (which is replaced)")
      ->required();
  command->add_option("--format", options->format, "tum (default) or rosbag")
      ->check(CLI::IsMember({"tum", "rosbag"}));
  command->add_option("--truth-spacing", options->truth_spacing,
                      "rosbag: truth.ply's point spacing in metres (every surface point within it of "
                      "a reference point; default 0.02)")
      ->check(CLI::Range(0.002, 1.0));
  command->add_option("--frames", options->frames, "Number of frames (default: the scenario's)")
      ->check(CLI::Range(1, kMaxFrames));
  command->add_option("--set", options->overrides,
                      "Override a scenario key, e.g. --set sensor.noise.model=none (repeatable)")
      ->allow_extra_args(false);  // one key=value per --set, so a scenario after it stays positional
  command->callback([options, &global] {
    std::vector<std::string> overrides = options->overrides;
    if (options->frames > 0) overrides.push_back("frames=" + std::to_string(options->frames));
    if (options->format == "rosbag")
      render_rosbag(options->scenario, overrides, options->out, options->truth_spacing, global.quiet);
    else
      render_sequence(options->scenario, overrides, options->out, global.quiet);
  });
}

}  // namespace sonomap::harness
