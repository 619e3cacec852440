// SPDX-License-Identifier: GPL-3.0-or-later
// Run keys: the settings of a run that are not part of the scenario file (raster.*, metrics.*,
// edf.*, mapper.*), given as "--set key=value" overrides. Each key is declared once, in the
// field tables (harness/app/config_fields.hpp); docs/settings.md lists them.
#pragma once

#include "audio/listen_stream.hpp"
#include "core/edf_raster.hpp"
#include "core/raster.hpp"
#include "eval/metrics.hpp"
#include "harness/app/frame_source.hpp"
#include "harness/app/mapper_factory.hpp"
#include "harness/support/fields.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace sonomap::harness {

// The binaural stream of `run --listen` (docs/sonification.md).
struct ListenSettings {
  audio::ListenConfig stream;
  double rt60 = 0.3;        // the synthesised room's reverberation (no --brir): docs/sonification.md
  bool woosh = true;        // unscanned sectors play the woosh
};

// Run keys (everything that is not part of the scenario file).
struct RunSettings {
  RasterConfig raster;
  eval::MetricsConfig metrics;
  bool ghost_tolerance_set = false;
  std::vector<Setting> mapper;
  // The EDF comparison (edf.*): on by default, every `edf_every`-th evaluated frame (about as
  // costly as integrating a frame: 110 ms median on the smoke room at half resolution).
  bool edf_enabled = true;
  int edf_every = 5;
  int edf_trace_rows = 4;  // rays per bin across the obstacle band (0: the sensor's height)
  EdfRasterConfig edf;
  bool edf_max_range_set = false;  // otherwise the raster's max_range
  ListenSettings listen;  // the stream of `run --listen` (listen.*)
};

// The run keys of `settings` by group ("raster.", "metrics.", "edf."), bound to its members.
struct FieldGroup {
  std::string prefix;
  FieldTable fields;
};
std::vector<FieldGroup> run_key_fields(RunSettings& settings);

// Splits "key=value" overrides into scenario overrides (returned in `scenario`, in order) and
// run settings (applied to `settings` and validated). Throws InputError naming the override.
void split_overrides(const std::vector<std::string>& overrides, std::vector<std::string>& scenario,
                     RunSettings& settings);

// summary.json's config of the run keys: {"raster": {...}, "metrics": {...}, "edf": {...}}.
nlohmann::json run_settings_json(const RunSettings& settings);

// Refuses, before any work, a map whose estimated memory (from the mapper's voxel size and the
// area of the scene's surfaces) exceeds `max_memory_gib` (0: half the machine's RAM).
void check_memory_budget(const Mapper& mapper, const FrameSource& source, double max_memory_gib);

// The key reference: every run key and mapper setting with default, bounds and meaning, as
// markdown table rows (docs/settings.md) or as `--help` lines.
std::string run_keys_markdown();
std::string run_keys_help();

}  // namespace sonomap::harness
