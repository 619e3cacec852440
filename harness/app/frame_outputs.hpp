// SPDX-License-Identifier: GPL-3.0-or-later
// What a run draws and plays for its chosen frames: pictures/ (circle, cylinder and, with the
// EDF comparison, the EDF arrows) and sweeps/ (a WAV and its event log per frame, and
// room.json, the room the BRIRs were synthesised for when no --brir was given).
#pragma once

#include "core/raster.hpp"
#include "harness/app/run_results.hpp"
#include "harness/app/run_setup.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace sonomap::audio {
class SweepRenderer;
}

namespace sonomap::harness {

// The sweep renderer, made at the first sweep: BRIRs from `brir_dir`, or synthesised for the
// room from the map around the listener (audio/room_from_map.hpp), recorded in room.json.
class SweepMaker {
 public:
  // Without a BRIR folder, the room is measured from the map's surface within room_radius
  // (horizontal) of the first swept frame's listener.
  SweepMaker(std::filesystem::path dir, std::filesystem::path brir_dir, double room_radius, bool quiet);
  ~SweepMaker();
  // dir/frame_NNNNNN.wav and its event log: the circular ranging of the frame's circle.
  void write(const FrameView& frame);
  const std::vector<SweepLevel>& levels() const { return levels_; }

 private:
  void make_renderer(const FrameView& frame);
  std::filesystem::path dir_, brir_dir_;
  double room_radius_;
  bool quiet_;
  std::unique_ptr<audio::SweepRenderer> renderer_;
  std::vector<SweepLevel> levels_;
};

class FrameOutputs {
 public:
  // Makes pictures/ and sweeps/ in `dir` when the schedule has frames for them.
  FrameOutputs(const std::filesystem::path& dir, const RunOptions& options,
               const FrameSchedule& schedule, std::string scenario_name, std::string mapper_name,
               const RasterConfig& raster);
  // The frame's pictures and sweep, if the schedule chose it for them.
  void write(const FrameView& frame);
  // Per sweep written: the gain applied and the loudness measured.
  const std::vector<SweepLevel>& sweep_levels() const { return sweeps_.levels(); }

 private:
  void draw_pictures(const FrameView& frame) const;
  std::filesystem::path pictures_;
  const FrameSchedule& schedule_;
  std::string scenario_name_, mapper_name_;
  RasterConfig raster_;
  SweepMaker sweeps_;
};

}  // namespace sonomap::harness
