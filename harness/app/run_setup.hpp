// SPDX-License-Identifier: GPL-3.0-or-later
// The first steps of a run: load the scenario (or recorded sequence) and the run keys, build
// the mapper, and plan which frames are evaluated, drawn and played.
#pragma once

#include "core/mapper.hpp"
#include "harness/app/frame_source.hpp"
#include "harness/app/run.hpp"
#include "harness/app/run_settings.hpp"
#include "harness/formats/run_summary.hpp"

#include <map>
#include <memory>
#include <string>

namespace sonomap::harness {

struct RunInputs {
  std::unique_ptr<FrameSource> source;
  RunSettings settings;
  std::map<std::string, std::string> tags;
  bool has_truth = false;  // the source knows the scene's true geometry
};

// Checks the options, splits --set into scenario and run keys and opens the frame source.
// Throws InputError naming the option, file, key or value.
RunInputs load_run_inputs(const RunOptions& options);

// The mapper --mapper names, with --voxel and the mapper.* keys. Unless metrics.ghost_tolerance
// was given, sets it to 2 voxels of this mapper (a ghost is more than 2 voxels too close).
std::unique_ptr<Mapper> build_mapper(const RunOptions& options, RunInputs& inputs);

// The summary's description of the run (scenario, seed, version, tags, the whole config); the
// metrics are filled in by RunResults.
RunSummary describe_run(const RunOptions& options, const RunInputs& inputs, const Mapper& mapper);

// Which frames get which work: every frame is sensed and integrated; every --every-th and the
// last are rasterised and evaluated; the EDF comparison runs on every edf.every-th evaluated
// frame, the last and the pictured ones; pictures and sweeps for the chosen frames (default:
// the last).
class FrameSchedule {
 public:
  FrameSchedule(const RunOptions& options, const RunSettings& settings, int frame_count);
  int frame_count() const { return frame_count_; }
  bool last(int frame) const { return frame == frame_count_ - 1; }
  bool evaluated(int frame) const { return frame % every_ == 0 || last(frame); }
  // `evaluated_before`: how many frames were evaluated before this one.
  bool edf(int frame, int evaluated_before) const;
  bool pictured(int frame) const { return chosen(picture_frames_, frame); }
  bool swept(int frame) const { return chosen(sweep_frames_, frame); }
  bool any_pictures() const { return any(picture_frames_); }
  bool any_sweeps() const { return any(sweep_frames_); }

 private:
  bool chosen(const std::vector<int>& list, int frame) const;
  static bool any(const std::vector<int>& list);
  int frame_count_, every_;
  bool edf_enabled_;
  int edf_every_;
  std::vector<int> picture_frames_, sweep_frames_;
};

}  // namespace sonomap::harness
