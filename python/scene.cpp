// SPDX-License-Identifier: GPL-3.0-or-later
#include "python/scene.hpp"

#include "core/rasterise_map.hpp"
#include "harness/app/mapper_registry.hpp"
#include "harness/support/errors.hpp"

#include <stdexcept>

namespace sonomap::python {
namespace {

harness::RunInputs load(const std::filesystem::path& file, const std::vector<std::string>& overrides,
                        int frames, std::optional<std::uint64_t> seed) {
  harness::RunOptions options;
  options.scenario = file;
  options.overrides = overrides;
  options.frames = frames;
  options.seed = seed;
  return harness::load_run_inputs(options);
}

// A frame's complaint (a bad pose) names the frame, as in `run`.
std::invalid_argument at_frame(const Frame& frame, const std::exception& e) {
  return std::invalid_argument("frame " + std::to_string(frame.index) + ": " + e.what());
}

}  // namespace

Scene::Scene(const std::filesystem::path& file, const std::vector<std::string>& overrides,
             int frames, std::optional<std::uint64_t> seed)
    : inputs_(load(file, overrides, frames, seed)) {}

std::shared_ptr<const SensedFrame> Scene::frame(int index) {
  if (index < 0 || index >= frame_count())
    throw std::out_of_range("frame " + std::to_string(index) + " is not in [0, " +
                            std::to_string(frame_count()) + ")");
  std::lock_guard<std::mutex> lock(render_mutex_);
  return std::make_shared<const SensedFrame>(SensedFrame{inputs_.source->frame(index)});
}

std::optional<eval::FrameTruth> Scene::frame_truth(
    const SensedFrame& frame, std::vector<eval::GroundTruthTriangle>& triangles) const {
  auto world = inputs_.source->truth(frame.sensed.frame.time);
  if (!world) return std::nullopt;
  triangles = std::move(*world);
  return eval::FrameTruth{&triangles, raster_origin(frame.sensed.world_T_body_true, ground_z())};
}

Rasters Scene::truth(const SensedFrame& frame) const {
  std::vector<eval::GroundTruthTriangle> triangles;
  const auto truth = frame_truth(frame, triangles);
  if (!truth) throw harness::InputError(name() + ": a recording has no ground truth");
  eval::GroundTruthRasters rasters = eval::ground_truth_rasters(triangles, truth->origin, raster());
  return {std::move(rasters.circle), std::move(rasters.cylinder)};
}

eval::FrameEvaluation Scene::score(const SensedFrame& frame, const Circle& circle,
                                   const Cylinder* cylinder) const {
  std::vector<eval::GroundTruthTriangle> triangles;
  const auto truth = frame_truth(frame, triangles);
  if (!truth) throw harness::InputError(name() + ": a recording has no ground truth to score against");
  const Cylinder unknown = make_cylinder(raster());
  const RasterOrigin origin = raster_origin(frame.sensed.frame.world_T_body, ground_z());
  const harness::RunSettings& s = inputs_.settings;
  return eval::evaluate_frame(circle, cylinder ? *cylinder : unknown, truth, nullptr, origin,
                              {s.raster, s.metrics, s.edf});
}

std::unique_ptr<Mapper> Scene::make_mapper(const std::string& name, double voxel,
                                           const std::vector<std::string>& settings) const {
  std::vector<harness::Setting> all = inputs_.settings.mapper;
  for (const std::string& s : settings) {
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw harness::InputError("mapper setting '" + s + "': expected key=value");
    all.push_back({s.substr(0, eq), s.substr(eq + 1), "mapper setting '" + s + "'"});
  }
  std::unique_ptr<Mapper> mapper = harness::make_mapper(name, voxel, all);
  harness::check_memory_budget(*mapper, *inputs_.source, 0.0);
  return mapper;
}

MapperSession::MapperSession(std::shared_ptr<Scene> scene, std::unique_ptr<Mapper> mapper)
    : scene_(std::move(scene)), mapper_(std::move(mapper)), rasteriser_(scene_->raster()) {}

void MapperSession::integrate(const SensedFrame& frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    mapper_->integrate(frame.sensed.frame);
  } catch (const std::invalid_argument& e) {
    throw at_frame(frame.sensed.frame, e);
  }
}

Rasters MapperSession::rasters(const SensedFrame& frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  const RasterOrigin origin = raster_origin(frame.sensed.frame.world_T_body, scene_->ground_z());
  rasterise_map(*mapper_, origin, rasteriser_, raster_scratch_);
  return {rasteriser_.circle(), rasteriser_.cylinder()};
}

}  // namespace sonomap::python
