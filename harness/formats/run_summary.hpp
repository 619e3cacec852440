// SPDX-License-Identifier: GPL-3.0-or-later
// A result directory's summary.json and timings.json as types (docs/results.md has the
// schema). Written and read in this one place: `run` writes them, `report` (and anything
// else) reads them back through the same structs, so a renamed field cannot break a reader
// silently. Undefined numbers (NaN) are JSON null.
#pragma once

#include "core/edf_raster.hpp"
#include "core/raster.hpp"
#include "eval/metrics.hpp"
#include "eval/moved_ghosts.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::harness {

// Bumped whenever a field is renamed, removed or changes meaning (adding one is compatible).
inline constexpr int kResultSchemaVersion = 1;

// The means over the evaluated frames where each metric is defined (NaN: none).
struct MeanMetrics {
  double coverage = NAN, rmse = NAN, rmse_off_edges = NAN, ghosts = NAN;
};

// One raster's metrics: the final evaluated frame's (none without truth) and the means.
struct RasterSummary {
  std::optional<eval::RasterMetrics> final_frame;
  MeanMetrics mean;
  static RasterSummary of(const std::vector<eval::RasterMetrics>& frames);
};

// The EDF comparison's bearing slip over the frames it ran on.
struct EdfSummary {
  std::size_t frames = 0;
  std::optional<SlipStats> final_slip;
  double mean_median_deg = NAN, mean_p90_deg = NAN;  // over frames with an observed bin
  static EdfSummary of(const std::vector<SlipStats>& frames);
};

// The EDF comparison's settings (run keys edf.*).
struct EdfSettings {
  bool enabled = true;
  int every = 5;
  int trace_rows = 4;
  EdfRasterConfig trace;
};

// Everything that decides a run's numbers; config_hash is taken over its JSON. `score` (which
// runs no mapper and no EDF comparison, every frame it is given) records no edf or every and
// adds the command it ran.
struct RunConfig {
  std::string mapper;
  std::map<std::string, std::string> mapper_config;  // as the mapper reports it (text)
  RasterConfig raster;
  eval::MetricsConfig metrics;
  std::optional<EdfSettings> edf;  // run only
  int frames = 0;
  std::optional<int> every;  // run only
  std::uint64_t seed = 0;
  std::vector<std::string> overrides;
  std::optional<std::string> command;  // score only: the external mapper's command ("" if none)
};

// The estimate files `score` scored, as given (or inside the result for --command).
struct ScoredFiles {
  std::string circle;
  std::optional<std::string> cylinder;  // null: no cylinder given
};

// One sweep written: the one gain applied and the loudness measured (summary.json "sweeps").
struct SweepLevel {
  std::string file;
  double gain_db = 0.0, loudness_lufs = 0.0, true_peak_dbtp = 0.0;
  bool peak_limited = false;
};

// The binaural stream of `run --listen` (summary.json "listen"): its one gain, its measured
// loudness, and how well each tap's direction survives the mix (localise_taps).
struct ListenSummary {
  std::string file;  // listen.wav
  std::string mode;  // world_locked | head_locked
  double duration_s = 0.0;
  int taps = 0;  // sounds played (taps and wooshes)
  double gain_db = 0.0, loudness_lufs = 0.0, true_peak_dbtp = 0.0;
  bool peak_limited = false;
  int localised_taps = 0;  // taps whose direction was estimated
  double median_error_deg = 0.0, p90_error_deg = 0.0;  // NaN without taps
};

struct RunSummary {
  int schema_version = kResultSchemaVersion;
  std::string scenario_name;
  std::string scenario_file;
  std::uint64_t seed = 0;
  std::string code_version;
  bool ground_truth = false;
  std::string ground_truth_note;  // where the truth came from; empty: the default text
  RunConfig config;
  int evaluated_frames = 0;
  std::map<std::string, std::string> tags;
  RasterSummary circle, cylinder;
  std::optional<RasterSummary> edf_circle;  // with the EDF comparison on
  std::optional<EdfSummary> edf;            // with the EDF comparison on
  std::vector<SweepLevel> sweeps;
  std::optional<ListenSummary> listen;
  std::optional<ScoredFiles> scored;  // score only
  // Per moving object of a simulated scenario, how its ghosts in the circle cleared
  // (docs/conventions.md "Moved-object ghosts"); empty without moving objects.
  std::vector<eval::MovedObjectClearing> moved_objects;
};

// How a stage's time grew over a long run: its median over the run's last kGrowthWindow
// frames against frames kGrowthWindow to 2 kGrowthWindow - 1 (the first kGrowthWindow are the
// map's start-up). For the room's 2700 frames: frames 2600-2699 against 100-199.
inline constexpr int kGrowthWindow = 100;
struct StageGrowth {
  int early_first = 0, early_last = 0, late_first = 0, late_last = 0;  // frames, inclusive
  double early_median_ms = 0.0, late_median_ms = 0.0;
  std::size_t early_samples = 0, late_samples = 0;  // the frames of each window it ran in
  double late_over_early = 0.0;
};

// timings.json: per stage, the median wall time over the frames it ran in and, in a run of
// 3 kGrowthWindow frames or more, its growth (where it ran in both windows, in a measurable
// time at the start).
struct StageTiming {
  double median_ms = 0.0;
  std::size_t samples = 0;
  std::optional<StageGrowth> growth;
};
using RunTimings = std::map<std::string, StageTiming>;
struct TimedFrame {
  int frame = 0;
  double ms = 0.0;
};
// `samples`: per stage, the frames it ran in (in any order) and their times; `frames_run`:
// the number of frames the run went through (frames 0 to frames_run - 1).
RunTimings summarise_timings(const std::map<std::string, std::vector<TimedFrame>>& samples, int frames_run);

// FNV-1a over the canonical JSON of a configuration: a short, stable hash.
std::string config_hash(const nlohmann::json& config);
std::string config_hash(const RunConfig& config);

void to_json(nlohmann::json& j, const RunConfig& c);
void from_json(const nlohmann::json& j, RunConfig& c);
void to_json(nlohmann::json& j, const RunSummary& s);
void from_json(const nlohmann::json& j, RunSummary& s);
void to_json(nlohmann::json& j, const StageTiming& t);
void from_json(const nlohmann::json& j, StageTiming& t);

// Reads DIR/summary.json. Throws InputError naming the file when it is missing, malformed,
// or of another schema version.
RunSummary read_run_summary(const std::filesystem::path& dir);
// Reads DIR/timings.json; empty when the file does not exist. Throws InputError if malformed.
RunTimings read_run_timings(const std::filesystem::path& dir);

}  // namespace sonomap::harness
