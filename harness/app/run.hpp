// SPDX-License-Identifier: GPL-3.0-or-later
// One run: sensor -> mapper -> rasters -> ground truth -> metrics (-> pictures, sweeps), written
// as one result directory. The directory appears whole (staged, renamed when complete).
//
// Result directory (documented in README.md, "Result directory"):
//   summary.json   scenario, seed, code version, mapper and raster config, config hash,
//                  per-raster final and mean metrics (byte-identical across reruns and threads)
//   frames.csv     one row per evaluated frame: pose and per-raster metrics
//   timings.csv    one row per frame: wall time of each stage in ms (the only file that varies)
//   circle.csv     frame,bin,estimate,truth (unknown = empty field)
//   cylinder.csv   frame,row,bin,estimate,truth
//   edf.csv        the final frame's EDF comparison per bin (run keys edf.*; core/edf_raster.hpp)
//   pictures/      frame_NNNNNN_circle.png, frame_NNNNNN_cylinder.png
//   sweeps/        frame_NNNNNN.wav, frame_NNNNNN.events.csv (circular ranging of the map's
//                  circle), room.json (the room the BRIRs were synthesised for)
//   map.ply        the mapper's final surface mesh (mappers that have one)
#pragma once

#include "core/mapper.hpp"
#include "core/rasteriser.hpp"
#include "harness/app/cli.hpp"

#include <nlohmann/json.hpp>

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
  bool quiet = false;
  // "key=value" labels recorded in summary.json (compare uses scenario=..., variant=...).
  std::vector<std::string> tags;
};

struct RunOutcome {
  std::filesystem::path dir;
  nlohmann::json summary;
};

RunOutcome run_scenario(const RunOptions& options);

// The map's circle and cylinder around `origin`, as a run builds them: the mapper's surface
// samples within the raster's max_range, added to the rasteriser reset on `origin`. `surface`
// is reused scratch and holds those samples afterwards. (`bench map` times this same call.)
void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   std::vector<Eigen::Vector3f>& surface);

// A one-screen summary of a run, for the terminal.
std::string summary_screen(const RunOutcome& outcome);

void add_run_command(CLI::App& app, const GlobalOptions& global);

}  // namespace sonomap::harness
