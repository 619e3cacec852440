// SPDX-License-Identifier: GPL-3.0-or-later
// The Python module's view of a scenario: the frame source and run keys `run` loads (same
// override syntax, tables and bounds), frames one at a time, the exact ground truth and the
// metrics of eval/ for any circle, and the built-in mappers through the mapper registry.
#pragma once

#include "core/mapper.hpp"
#include "core/rasterise_map.hpp"
#include "core/rasteriser.hpp"
#include "eval/evaluate_frame.hpp"
#include "harness/app/run_setup.hpp"

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::python {

// One sensed frame: what the mapper gets and the true body pose the truth is seen from.
struct SensedFrame {
  harness::SourceFrame sensed;
};

struct Rasters {
  Circle circle;
  Cylinder cylinder;
};

class Scene {
 public:
  // Throws harness::InputError naming the file, line and key (or the override).
  Scene(const std::filesystem::path& file, const std::vector<std::string>& overrides, int frames,
        std::optional<std::uint64_t> seed);

  std::string name() const { return inputs_.source->name(); }
  int frame_count() const { return inputs_.source->frame_count(); }
  std::uint64_t seed() const { return inputs_.source->seed(); }
  double ground_z() const { return inputs_.source->ground_z(); }
  bool has_truth() const { return inputs_.has_truth; }
  const RasterConfig& raster() const { return inputs_.settings.raster; }
  const eval::MetricsConfig& metrics() const { return inputs_.settings.metrics; }

  // std::out_of_range unless 0 <= index < frame_count().
  std::shared_ptr<const SensedFrame> frame(int index);
  // The exact rasters around the frame's TRUE body pose at its time (eval/ground_truth).
  // InputError for a recording (no ground truth).
  Rasters truth(const SensedFrame& frame) const;
  // The metrics `run` writes for this circle (and cylinder, if given) against the truth.
  eval::FrameEvaluation score(const SensedFrame& frame, const Circle& circle,
                              const Cylinder* cylinder) const;
  // A built-in (or registered) mapper with the scenario's mapper.* keys, then `settings`
  // ("key=value"), as `run --mapper NAME --voxel V` builds it, under run's memory budget.
  std::unique_ptr<Mapper> make_mapper(const std::string& name, double voxel,
                                      const std::vector<std::string>& settings) const;

 private:
  std::optional<eval::FrameTruth> frame_truth(const SensedFrame& frame,
                                              std::vector<eval::GroundTruthTriangle>& triangles) const;
  harness::RunInputs inputs_;
  std::mutex render_mutex_;  // the simulator renders one frame at a time
};

// A mapper fed frame by frame, with the rasters around the listener the way `run` makes them.
class MapperSession {
 public:
  MapperSession(std::shared_ptr<Scene> scene, std::unique_ptr<Mapper> mapper);
  const Mapper& mapper() const { return *mapper_; }
  // ValueError (std::invalid_argument) naming the frame for a frame the mapper rejects.
  void integrate(const SensedFrame& frame);
  // The circle and cylinder of the map around the frame's ESTIMATED body pose.
  Rasters rasters(const SensedFrame& frame);

 private:
  std::shared_ptr<Scene> scene_;
  std::unique_ptr<Mapper> mapper_;
  Rasteriser rasteriser_;
  RasterScratch raster_scratch_;
  std::mutex mutex_;
};

}  // namespace sonomap::python
