// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/run_setup.hpp"

#include "harness/app/cli.hpp"
#include "harness/app/mapper_factory.hpp"
#include "harness/app/run_results.hpp"
#include "harness/support/errors.hpp"

#include <algorithm>

namespace sonomap::harness {
RunInputs load_run_inputs(const RunOptions& options) {
  if (options.frames < 0) throw InputError("--frames must be positive, got " + std::to_string(options.frames));
  if (options.every < 1) throw InputError("--every must be at least 1, got " + std::to_string(options.every));
  RunInputs inputs;
  inputs.tags = parse_tags(options.tags);
  std::vector<std::string> scenario_overrides;
  split_overrides(options.overrides, scenario_overrides, inputs.settings);
  inputs.source = open_frame_source(options.scenario, std::move(scenario_overrides),
                                    options.frames, options.seed);
  inputs.has_truth = inputs.source->truth(0.0).has_value() || inputs.source->truth_cloud() != nullptr;
  return inputs;
}

std::unique_ptr<Mapper> build_mapper(const RunOptions& options, RunInputs& inputs) {
  RunSettings& settings = inputs.settings;
  auto mapper = make_mapper(options.mapper, options.voxel, settings.mapper);
  // docs/conventions.md: a ghost is more than 2 voxels closer than the truth.
  if (!settings.ghost_tolerance_set && mapper_voxel(*mapper) > 0.0)
    settings.metrics.ghost_tolerance = 2.0 * mapper_voxel(*mapper);
  // The Open3D peer fuses frame.depth (the image), not the points.
  if (mapper->name() == "open3d" && !inputs.source->depth_images())
    throw InputError(options.scenario.string() + ": mapper " + mapper->name() +
                     " fuses depth images, but the depth topic holds unorganised point clouds (height 1): "
                     "record an organised cloud (one point per pixel) or a depth image, or use another mapper");
  check_memory_budget(*mapper, *inputs.source, options.max_memory_gib);
  return mapper;
}

RunSummary describe_run(const RunOptions& options, const RunInputs& inputs, const Mapper& mapper) {
  const FrameSource& source = *inputs.source;
  const RunSettings& settings = inputs.settings;
  RunSummary s;
  s.scenario_name = source.name();
  s.scenario_file = options.scenario.string();
  s.seed = source.seed();
  s.code_version = code_version();
  s.ground_truth = inputs.has_truth;
  s.ground_truth_note = source.truth_note();
  s.tags = inputs.tags;
  RunConfig& c = s.config;
  c.mapper = mapper.name();
  for (const auto& [key, value] : mapper_config_entries(mapper)) c.mapper_config[key] = value;
  c.raster = settings.raster;
  c.metrics = settings.metrics;
  c.edf = EdfSettings{settings.edf_enabled, settings.edf_every, settings.edf_trace_rows, settings.edf};
  c.frames = source.frame_count();
  c.every = options.every;
  c.seed = source.seed();
  c.overrides = options.overrides;
  return s;
}

FrameSchedule::FrameSchedule(const RunOptions& options, const RunSettings& settings, int frame_count)
    : frame_count_(frame_count), every_(options.every), edf_enabled_(settings.edf_enabled),
      edf_every_(settings.edf_every), picture_frames_(options.picture_frames),
      sweep_frames_(options.sweep_frames) {}

bool FrameSchedule::edf(int frame, int evaluated_before) const {
  return edf_enabled_ && (evaluated_before % edf_every_ == 0 || last(frame) || pictured(frame));
}

bool FrameSchedule::chosen(const std::vector<int>& list, int frame) const {
  if (list.empty()) return last(frame);
  return std::find(list.begin(), list.end(), frame) != list.end();
}

bool FrameSchedule::any(const std::vector<int>& list) {
  return list.empty() || std::any_of(list.begin(), list.end(), [](int f) { return f >= 0; });
}

}  // namespace sonomap::harness
