// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/run_summary.hpp"

#include "harness/support/errors.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

namespace fs = std::filesystem;
using nlohmann::json;

namespace sonomap::harness {
namespace {

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double number_of(const json& v) { return v.is_null() ? NAN : v.get<double>(); }

// RasterMetrics' fields as summary.json names them (one list for writing and reading): the
// ratios, which may be undefined (null), and the counts.
template <typename Metrics>  // eval::RasterMetrics, const or not
auto ratio_fields(Metrics& m) {
  using Field = std::pair<const char*, decltype(&m.coverage)>;
  return std::array<Field, 3>{Field{"coverage", &m.coverage}, Field{"rmse", &m.rmse},
                              Field{"rmse_off_edges", &m.rmse_off_edges}};
}
template <typename Metrics>
auto count_fields(Metrics& m) {
  using Field = std::pair<const char*, decltype(&m.cells)>;
  return std::array<Field, 6>{Field{"edge_cells", &m.edge_cells}, Field{"ghosts", &m.ghosts},
                              Field{"known_in_both", &m.known_in_both},
                              Field{"truth_occupied", &m.truth_occupied},
                              Field{"estimate_known", &m.estimate_known}, Field{"cells", &m.cells}};
}

json metrics_json_of(const eval::RasterMetrics& m) {
  json j = json::object();
  for (const auto& [key, value] : ratio_fields(m)) j[key] = number(*value);
  for (const auto& [key, value] : count_fields(m)) j[key] = *value;
  return j;
}

eval::RasterMetrics metrics_of(const json& j) {
  eval::RasterMetrics m;
  for (const auto& [key, value] : ratio_fields(m)) *value = number_of(j.at(key));
  for (const auto& [key, value] : count_fields(m)) j.at(key).get_to(*value);
  return m;
}

json raster_summary_json_of(const RasterSummary& r) {
  const MeanMetrics& m = r.mean;
  return json{{"final", r.final_frame ? metrics_json_of(*r.final_frame) : json(nullptr)},
              {"mean", {{"coverage", number(m.coverage)}, {"rmse", number(m.rmse)},
                        {"rmse_off_edges", number(m.rmse_off_edges)}, {"ghosts", number(m.ghosts)}}}};
}

RasterSummary raster_summary_of(const json& j) {
  RasterSummary r;
  if (!j.at("final").is_null()) r.final_frame = metrics_of(j.at("final"));
  const json& m = j.at("mean");
  r.mean = {number_of(m.at("coverage")), number_of(m.at("rmse")), number_of(m.at("rmse_off_edges")),
            number_of(m.at("ghosts"))};
  return r;
}

json slip_json(const SlipStats& s) {
  return json{{"median_deg", number(s.median_deg)}, {"p90_deg", number(s.p90_deg)},
              {"observed", s.observed}};
}

json edf_summary_json(const EdfSummary& e) {
  return json{{"frames", e.frames},
              {"slip", {{"final", e.final_slip ? slip_json(*e.final_slip) : json(nullptr)},
                        {"mean", {{"median_deg", number(e.mean_median_deg)},
                                  {"p90_deg", number(e.mean_p90_deg)}}}}}};
}

EdfSummary edf_summary_of(const json& j) {
  EdfSummary e;
  j.at("frames").get_to(e.frames);
  const json& slip = j.at("slip");
  if (const json& f = slip.at("final"); !f.is_null())
    e.final_slip = SlipStats{f.at("observed").get<int>(), number_of(f.at("median_deg")),
                             number_of(f.at("p90_deg"))};
  e.mean_median_deg = number_of(slip.at("mean").at("median_deg"));
  e.mean_p90_deg = number_of(slip.at("mean").at("p90_deg"));
  return e;
}

json optional_int(const std::optional<int>& v) { return v ? json(*v) : json(nullptr); }
std::optional<int> optional_int_of(const json& v) { return v.is_null() ? std::nullopt : std::optional(v.get<int>()); }

json moved_object_json(const eval::MovedObjectClearing& m) {
  return json{{"name", m.name},
              {"seen_empty_frame", optional_int(m.seen_empty_frame)},
              {"cleared", m.cleared()},
              {"clearing_frames", optional_int(m.clearing_frames)},
              {"ghost_bins_at_end", m.ghost_bins_at_end},
              {"unseen_ghost_bins_at_end", m.unseen_ghost_bins_at_end},
              {"max_ghost_bins", m.max_ghost_bins},
              {"ghost_frames", m.ghost_frames}};
}

eval::MovedObjectClearing moved_object_of(const json& j) {
  eval::MovedObjectClearing m;
  j.at("name").get_to(m.name);
  m.seen_empty_frame = optional_int_of(j.at("seen_empty_frame"));
  m.clearing_frames = optional_int_of(j.at("clearing_frames"));
  j.at("ghost_bins_at_end").get_to(m.ghost_bins_at_end);
  j.at("unseen_ghost_bins_at_end").get_to(m.unseen_ghost_bins_at_end);
  j.at("max_ghost_bins").get_to(m.max_ghost_bins);
  j.at("ghost_frames").get_to(m.ghost_frames);
  return m;
}

template <typename T>
T read_json_file(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot read");
  try {
    return json::parse(in).get<T>();
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": not a sonomap result file: " + e.what());
  } catch (const InputError& e) {
    throw InputError(file.string() + ": " + e.what());
  }
}

}  // namespace

RasterSummary RasterSummary::of(const std::vector<eval::RasterMetrics>& frames) {
  RasterSummary r;
  if (frames.empty()) return r;
  r.final_frame = frames.back();
  double cov = 0, rmse = 0, rmse_off = 0, ghosts = 0;
  int n_cov = 0, n_rmse = 0, n_off = 0;
  for (const auto& m : frames) {
    if (std::isfinite(m.coverage)) cov += m.coverage, ++n_cov;
    if (std::isfinite(m.rmse)) rmse += m.rmse, ++n_rmse;
    if (std::isfinite(m.rmse_off_edges)) rmse_off += m.rmse_off_edges, ++n_off;
    ghosts += m.ghosts;
  }
  r.mean = {n_cov ? cov / n_cov : NAN, n_rmse ? rmse / n_rmse : NAN,
            n_off ? rmse_off / n_off : NAN, ghosts / frames.size()};
  return r;
}

EdfSummary EdfSummary::of(const std::vector<SlipStats>& frames) {
  EdfSummary e;
  e.frames = frames.size();
  if (!frames.empty()) e.final_slip = frames.back();
  double median = 0.0, p90 = 0.0;
  int n = 0;
  for (const SlipStats& s : frames)
    if (s.observed > 0) median += s.median_deg, p90 += s.p90_deg, ++n;
  if (n) e.mean_median_deg = median / n, e.mean_p90_deg = p90 / n;
  return e;
}

namespace {

// The median of the times of the frames in [first, last] (the upper one of an even count), and
// how many there were; none when there were none.
std::optional<std::pair<double, std::size_t>> median_between(const std::vector<TimedFrame>& samples, int first,
                                                              int last) {
  std::vector<double> values;
  for (const TimedFrame& s : samples)
    if (s.frame >= first && s.frame <= last) values.push_back(s.ms);
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  return std::make_pair(values[values.size() / 2], values.size());
}

std::optional<StageGrowth> growth_of(const std::vector<TimedFrame>& samples, int frames_run) {
  if (frames_run < 3 * kGrowthWindow) return std::nullopt;
  StageGrowth g{kGrowthWindow, 2 * kGrowthWindow - 1, frames_run - kGrowthWindow, frames_run - 1};
  const auto early = median_between(samples, g.early_first, g.early_last);
  const auto late = median_between(samples, g.late_first, g.late_last);
  if (!early || !late || !(early->first > 0.0)) return std::nullopt;
  std::tie(g.early_median_ms, g.early_samples) = *early;
  std::tie(g.late_median_ms, g.late_samples) = *late;
  g.late_over_early = g.late_median_ms / g.early_median_ms;
  return g;
}

}  // namespace

RunTimings summarise_timings(const std::map<std::string, std::vector<TimedFrame>>& samples, int frames_run) {
  RunTimings timings;
  for (const auto& [name, stage] : samples) {
    const auto all = median_between(stage, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
    if (!all) continue;
    timings[name] = {all->first, all->second, growth_of(stage, frames_run)};
  }
  return timings;
}

std::string config_hash(const json& config) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : config.dump()) h = (h ^ c) * 1099511628211ull;
  return fmt::format("{:016x}", h);
}

std::string config_hash(const RunConfig& config) { return config_hash(json(config)); }

void to_json(json& j, const RunConfig& c) {
  j = json{{"mapper", c.mapper}, {"mapper_config", json(c.mapper_config)},
           {"raster", {{"azimuth_bins", c.raster.azimuth_bins}, {"band_min", c.raster.band_min},
                       {"band_max", c.raster.band_max}, {"row_height", c.raster.row_height},
                       {"max_range", c.raster.max_range}}},
           {"metrics", {{"ghost_tolerance", c.metrics.ghost_tolerance},
                        {"edge_jump", c.metrics.edge_jump}}},
           {"frames", c.frames}, {"seed", c.seed}, {"overrides", c.overrides}};
  if (c.edf) {
    const EdfRasterConfig& t = c.edf->trace;
    j["edf"] = {{"enabled", c.edf->enabled}, {"every", c.edf->every},
                {"sample_radius", t.sample_radius}, {"hit_tolerance", t.hit_tolerance},
                {"max_steps", t.max_steps}, {"max_range", t.max_range},
                {"trace_rows", c.edf->trace_rows}, {"trace_heights", t.trace_heights}};
  }
  if (c.every) j["every"] = *c.every;
  if (c.command) j["command"] = *c.command;
}

void from_json(const json& j, RunConfig& c) {
  j.at("mapper").get_to(c.mapper);
  j.at("mapper_config").get_to(c.mapper_config);
  const json& r = j.at("raster");
  r.at("azimuth_bins").get_to(c.raster.azimuth_bins);
  r.at("band_min").get_to(c.raster.band_min);
  r.at("band_max").get_to(c.raster.band_max);
  r.at("row_height").get_to(c.raster.row_height);
  r.at("max_range").get_to(c.raster.max_range);
  j.at("metrics").at("ghost_tolerance").get_to(c.metrics.ghost_tolerance);
  j.at("metrics").at("edge_jump").get_to(c.metrics.edge_jump);
  if (j.contains("edf")) {
    const json& e = j.at("edf");
    EdfSettings& edf = c.edf.emplace();
    e.at("enabled").get_to(edf.enabled);
    e.at("every").get_to(edf.every);
    e.at("trace_rows").get_to(edf.trace_rows);
    e.at("sample_radius").get_to(edf.trace.sample_radius);
    e.at("hit_tolerance").get_to(edf.trace.hit_tolerance);
    e.at("max_steps").get_to(edf.trace.max_steps);
    e.at("max_range").get_to(edf.trace.max_range);
    e.at("trace_heights").get_to(edf.trace.trace_heights);
  }
  j.at("frames").get_to(c.frames);
  if (j.contains("every")) c.every = j.at("every").get<int>();
  j.at("seed").get_to(c.seed);
  j.at("overrides").get_to(c.overrides);
  if (j.contains("command")) c.command = j.at("command").get<std::string>();
}

void to_json(json& j, const RunSummary& s) {
  j = json{{"schema_version", s.schema_version},
           {"scenario", {{"name", s.scenario_name}, {"file", s.scenario_file}}},
           {"seed", s.seed},
           {"code_version", s.code_version},
           {"ground_truth", s.ground_truth},
           {"ground_truth_note", !s.ground_truth_note.empty() ? s.ground_truth_note
                                 : s.ground_truth ? "exact wedge minima from the scenario's geometry"
                                                  : "recorded data: no ground truth, no metrics"},
           {"config", s.config},
           {"config_hash", config_hash(s.config)},
           {"evaluated_frames", s.evaluated_frames},
           {"tags", json(s.tags)},
           {"metrics", {{"circle", raster_summary_json_of(s.circle)},
                        {"cylinder", raster_summary_json_of(s.cylinder)}}}};
  if (s.edf_circle) j["metrics"]["edf_circle"] = raster_summary_json_of(*s.edf_circle);
  if (s.edf) j["edf"] = edf_summary_json(*s.edf);
  if (s.scored)
    j["scored"] = {{"circle", s.scored->circle},
                   {"cylinder", s.scored->cylinder ? json(*s.scored->cylinder) : json(nullptr)}};
  j["sweeps"] = json::array();
  for (const SweepLevel& l : s.sweeps)
    j["sweeps"].push_back({{"file", l.file}, {"gain_db", l.gain_db}, {"loudness_lufs", l.loudness_lufs},
                           {"true_peak_dbtp", l.true_peak_dbtp}, {"peak_limited", l.peak_limited}});
  j["moved_objects"] = json::array();
  for (const eval::MovedObjectClearing& m : s.moved_objects) j["moved_objects"].push_back(moved_object_json(m));
  if (s.listen) {
    const ListenSummary& l = *s.listen;
    j["listen"] = {{"file", l.file}, {"mode", l.mode}, {"duration_s", l.duration_s},
                   {"taps", l.taps}, {"gain_db", l.gain_db}, {"loudness_lufs", l.loudness_lufs},
                   {"true_peak_dbtp", l.true_peak_dbtp}, {"peak_limited", l.peak_limited},
                   {"localisation", {{"taps", l.localised_taps},
                                     {"median_error_deg", l.median_error_deg},
                                     {"p90_error_deg", l.p90_error_deg}}}};
  }
}

void from_json(const json& j, RunSummary& s) {
  if (!j.contains("schema_version"))
    throw InputError("no schema_version: written by an older sonomap; run it again");
  j.at("schema_version").get_to(s.schema_version);
  if (s.schema_version != kResultSchemaVersion)
    throw InputError(fmt::format("schema_version {}, this sonomap reads {}", s.schema_version,
                                 kResultSchemaVersion));
  j.at("scenario").at("name").get_to(s.scenario_name);
  j.at("scenario").at("file").get_to(s.scenario_file);
  j.at("seed").get_to(s.seed);
  j.at("code_version").get_to(s.code_version);
  j.at("ground_truth").get_to(s.ground_truth);
  j.at("config").get_to(s.config);
  j.at("evaluated_frames").get_to(s.evaluated_frames);
  j.at("tags").get_to(s.tags);
  const json& m = j.at("metrics");
  s.circle = raster_summary_of(m.at("circle"));
  s.cylinder = raster_summary_of(m.at("cylinder"));
  if (m.contains("edf_circle")) s.edf_circle = raster_summary_of(m.at("edf_circle"));
  if (j.contains("edf")) s.edf = edf_summary_of(j.at("edf"));
  if (j.contains("scored")) {
    ScoredFiles& f = s.scored.emplace();
    j.at("scored").at("circle").get_to(f.circle);
    if (const json& c = j.at("scored").at("cylinder"); !c.is_null()) f.cylinder = c.get<std::string>();
  }
  for (const json& l : j.value("sweeps", json::array()))
    s.sweeps.push_back({l.at("file").get<std::string>(), l.at("gain_db").get<double>(),
                        number_of(l.at("loudness_lufs")), number_of(l.at("true_peak_dbtp")),
                        l.at("peak_limited").get<bool>()});
  for (const json& m : j.value("moved_objects", json::array())) s.moved_objects.push_back(moved_object_of(m));
  if (j.contains("listen")) {
    const json& l = j.at("listen");
    const json& where = l.at("localisation");
    s.listen = ListenSummary{l.at("file").get<std::string>(), l.at("mode").get<std::string>(),
                             l.at("duration_s").get<double>(), l.at("taps").get<int>(),
                             l.at("gain_db").get<double>(), number_of(l.at("loudness_lufs")),
                             number_of(l.at("true_peak_dbtp")), l.at("peak_limited").get<bool>(),
                             where.at("taps").get<int>(), number_of(where.at("median_error_deg")),
                             number_of(where.at("p90_error_deg"))};
  }
}

void to_json(json& j, const StageTiming& t) {
  j = json{{"median_ms", t.median_ms}, {"samples", t.samples}};
  if (!t.growth) return;
  const StageGrowth& g = *t.growth;
  j["growth"] = json{{"early_frames", {g.early_first, g.early_last}},
                     {"early_median_ms", g.early_median_ms},
                     {"early_samples", g.early_samples},
                     {"late_frames", {g.late_first, g.late_last}},
                     {"late_median_ms", g.late_median_ms},
                     {"late_samples", g.late_samples},
                     {"late_over_early", g.late_over_early}};
}
void from_json(const json& j, StageTiming& t) {
  j.at("median_ms").get_to(t.median_ms);
  j.at("samples").get_to(t.samples);
  t.growth.reset();
  if (!j.contains("growth")) return;  // a short run's, or an older file's
  const json& g = j.at("growth");
  StageGrowth& out = t.growth.emplace();
  g.at("early_frames").at(0).get_to(out.early_first);
  g.at("early_frames").at(1).get_to(out.early_last);
  g.at("late_frames").at(0).get_to(out.late_first);
  g.at("late_frames").at(1).get_to(out.late_last);
  g.at("early_median_ms").get_to(out.early_median_ms);
  g.at("late_median_ms").get_to(out.late_median_ms);
  g.at("early_samples").get_to(out.early_samples);
  g.at("late_samples").get_to(out.late_samples);
  g.at("late_over_early").get_to(out.late_over_early);
}

RunSummary read_run_summary(const fs::path& dir) {
  return read_json_file<RunSummary>(dir / "summary.json");
}

RunTimings read_run_timings(const fs::path& dir) {
  const fs::path file = dir / "timings.json";
  return fs::exists(file) ? read_json_file<RunTimings>(file) : RunTimings{};
}

}  // namespace sonomap::harness
