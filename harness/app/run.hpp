// SPDX-License-Identifier: GPL-3.0-or-later
// One run: sensor -> mapper -> rasters -> evaluation (ground truth, metrics, EDF) -> pictures,
// sweeps, written as one result directory (docs/results.md). The directory appears whole
// (staged, renamed when complete). The steps live in their own units:
//   run_setup      load the scenario and run keys, build the mapper, plan the frames
//   core/rasterise_map, eval/evaluate_frame   the per-frame computation
//   run_results    frames.csv, circle.csv, cylinder.csv, edf.csv, timings, summary.json
//   frame_outputs  pictures/ and sweeps/ for the chosen frames
//   video_maker    run.mp4 (--video)
#pragma once

#include "harness/app/cli.hpp"
#include "harness/formats/run_summary.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::harness {

struct RunOptions {
  std::filesystem::path scenario;  // YAML scenario, or a TUM RGB-D directory (recorded data)
  // "key=value": scenario keys (see scenes/README.md) and run keys: mapper.*, raster.*,
  // metrics.*, edf.*, sonify.* (see README.md).
  std::vector<std::string> overrides;
  std::filesystem::path out;
  int frames = 0;  // 0: as the scenario says
  int every = 1;   // rasters, truth and metrics every K-th frame (and the last); mapping: all
  std::string mapper = "vdb_gpdf";
  double voxel = 0.0;  // global voxel size in metres; 0: the mapper's default
  std::optional<std::uint64_t> seed;
  double max_memory_gib = 0.0;  // map memory budget; 0: half the machine's RAM
  std::vector<int> picture_frames;  // empty: the last evaluated frame; -1: none
  std::vector<int> sweep_frames;    // empty: the last evaluated frame; -1: none
  // BRIR directory (one SOFA per distance) for the sweeps; empty: synthesise a shoebox room
  // from the map's bounding box around the listener at the first sweep (the paper's "room
  // from the map").
  std::filesystem::path brir_dir;
  bool write_rasters = true;
  bool listen = false;  // listen.wav and listen_events.csv (harness/app/listen_step.hpp)
  bool video = false;  // run.mp4 (harness/app/video_maker.hpp)
  bool quiet = false;
  // "key=value" labels recorded in summary.json (compare uses scenario=..., variant=...).
  std::vector<std::string> tags;
};

struct RunOutcome {
  std::filesystem::path dir;
  RunSummary summary;  // as written to dir/summary.json
};

RunOutcome run_scenario(const RunOptions& options);

// A one-screen summary of a run, for the terminal.
std::string summary_screen(const RunOutcome& outcome);

void add_run_command(CLI::App& app, const GlobalOptions& global);

}  // namespace sonomap::harness
