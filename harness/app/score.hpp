// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap score`: rasters made by any program, judged against the exact ground truth. The
// input is the scenario the program saw and its circle (and optionally cylinder) estimates in
// the CSV schema `run` writes (circle_io.hpp); the output is a result directory like a run's
// (summary.json, frames.csv, circle.csv and cylinder.csv with the truth beside the estimate,
// pictures), so `report`, `compare` and `diff` treat it as one.
//
// With `command`, score first runs an external mapper (compare's `command:` variants): the
// scenario rendered once as a TUM RGB-D sequence (cached under `sequence_cache`), then the
// command with {sequence}, {out} and {frames} substituted (no shell), with a timeout; it must
// write {out}/circle.csv and may write {out}/cylinder.csv.
#pragma once

#include "harness/app/cli.hpp"
#include "harness/formats/run_summary.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::harness {

struct ScoreOptions {
  std::filesystem::path scenario;  // YAML scenario (the truth comes from its geometry)
  std::filesystem::path circle;    // frame,bin,estimate[,truth]
  std::filesystem::path cylinder;  // frame,row,bin,estimate[,truth]; empty: none
  std::filesystem::path out;
  std::vector<std::string> overrides;  // scenario keys and raster.* / metrics.* run keys
  int frames = 0;                      // 0: as the scenario says
  std::optional<std::uint64_t> seed;
  std::string name = "external";  // recorded as the mapper's name
  std::vector<int> picture_frames;  // empty: the last scored frame; -1: none
  std::vector<std::string> tags;    // key=value labels (compare: scenario, variant, sweep)
  // External mapper (compare's command variants): the command line, its time limit in seconds
  // and where rendered sequences are kept between runs.
  std::string command;
  double timeout = 600.0;
  std::filesystem::path sequence_cache;
  bool quiet = false;
};

// Scores the estimates and writes the result directory (atomically). Returns its summary.
RunSummary score_rasters(const ScoreOptions& options);

void add_score_command(CLI::App& app, const GlobalOptions& global);

}  // namespace sonomap::harness
