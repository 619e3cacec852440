// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap render SCENARIO.yaml --out DIR`: the simulated depth frames as a TUM RGB-D sequence.
#include "harness/app/render_command.hpp"

#include "harness/app/cli.hpp"
#include "harness/app/frame_source.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/tum_io.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"
#include "sim/simulation.hpp"

#include <cstdio>
#include <memory>
#include <system_error>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

struct RenderOptions {
  std::string scenario;
  std::string out;
  int frames = 0;  // 0: the scenario's
  std::vector<std::string> overrides;
};

}  // namespace

void render_sequence(const fs::path& scenario_file, const std::vector<std::string>& overrides,
                     const fs::path& out, bool quiet) {
  const sim::Scenario scenario = load_scenario(scenario_file, overrides);

  CameraFile camera{scenario.name, scenario.camera, kTumDepthScale};
  if (camera.camera.max_range * camera.depth_scale > 65535.0)
    throw InputError(scenario_file.string(), 0, "sensor.max_range",
                     "a 16-bit PNG at " + std::to_string(static_cast<int>(kTumDepthScale)) +
                         " per metre holds depths up to " + std::to_string(65535.0 / kTumDepthScale) +
                         " m; lower max_range to render this scenario");

  std::unique_ptr<sim::Simulation> simulation;
  try {
    simulation = std::make_unique<sim::Simulation>(scenario);
  } catch (const std::invalid_argument& e) {
    throw InputError(scenario_file.string(), 0, "", e.what());
  }

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
                "camera.yaml");
  command->add_option("scenario", options->scenario, "Scenario file (format: scenes/README.md)")
      ->required();
  command->add_option("--out", options->out,
                      "Output directory: written whole or not at all; new, empty, or an earlier "
                      "sonomap result (which is replaced)")
      ->required();
  command->add_option("--frames", options->frames, "Number of frames (default: the scenario's)")
      ->check(CLI::Range(1, kMaxFrames));
  command->add_option("--set", options->overrides,
                      "Override a scenario key, e.g. --set sensor.noise.model=none (repeatable)")
      ->allow_extra_args(false);  // one key=value per --set, so a scenario after it stays positional
  command->callback([options, &global] {
    std::vector<std::string> overrides = options->overrides;
    if (options->frames > 0) overrides.push_back("frames=" + std::to_string(options->frames));
    render_sequence(options->scenario, overrides, options->out, global.quiet);
  });
}

}  // namespace sonomap::harness
