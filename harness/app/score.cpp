// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/score.hpp"

#include "harness/app/frame_source.hpp"
#include "harness/app/render_command.hpp"
#include "harness/app/run_results.hpp"
#include "harness/app/run_settings.hpp"

#include "eval/evaluate_frame.hpp"
#include "eval/ground_truth.hpp"
#include "eval/metrics.hpp"
#include "harness/formats/circle_io.hpp"
#include "harness/report/pictures.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"
#include "harness/support/subprocess.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fcntl.h>
#include <fstream>
#include <sys/file.h>
#include <unistd.h>

namespace fs = std::filesystem;
using nlohmann::json;

namespace sonomap::harness {
namespace {

// The command's words, split at blanks outside quotes ('...' or "..."), no shell.
std::vector<std::string> split_command(const std::string& command) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (char c : command) {
    if (quote) {
      if (c == quote) quote = 0;
      else word += c;
    } else if (c == '\'' || c == '"') {
      quote = c, in_word = true;
    } else if (c == ' ' || c == '\t') {
      if (in_word) words.push_back(word), word.clear(), in_word = false;
    } else {
      word += c, in_word = true;
    }
  }
  if (quote) throw InputError("command '" + command + "': unterminated quote");
  if (in_word) words.push_back(word);
  if (words.empty()) throw InputError("command is empty");
  return words;
}

// {sequence}, {out} and {frames} replaced in every word; any other {name} is an error.
std::vector<std::string> substitute(std::vector<std::string> words, const json& values,
                                    const std::string& command) {
  for (std::string& w : words) {
    std::string out;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const std::size_t close = w.find('}', i);
      if (w[i] != '{' || close == std::string::npos) {
        out += w[i];
        continue;
      }
      const std::string name = w.substr(i + 1, close - i - 1);
      if (!values.contains(name))
        throw InputError("command '" + command + "': unknown placeholder {" + name +
                         "} (known: {sequence}, {out}, {frames})");
      out += values[name].get<std::string>();
      i = close;
    }
    w = out;
  }
  return words;
}

// The scenario rendered as a TUM sequence, once per (scenario, overrides) under `cache`; a
// lock file keeps concurrent runs of a sweep from rendering the same sequence twice.
fs::path cached_sequence(const ScoreOptions& o, const std::vector<std::string>& scenario_overrides,
                         const std::string& name, std::uint64_t seed, int frames) {
  std::vector<std::string> overrides = scenario_overrides;
  overrides.push_back("frames=" + std::to_string(frames));
  overrides.push_back("seed=" + std::to_string(seed));
  const json key{{"scenario", fs::absolute(o.scenario).lexically_normal().string()}, {"overrides", overrides}};
  const fs::path dir = o.sequence_cache / fmt::format("{}-s{}-{}", name, seed, config_hash(key).substr(0, 8));
  fs::create_directories(o.sequence_cache);
  const fs::path lock_file = o.sequence_cache / ".lock";
  const int lock = ::open(lock_file.c_str(), O_RDWR | O_CREAT, 0644);
  if (lock < 0 || ::flock(lock, LOCK_EX) != 0)
    throw std::runtime_error("cannot lock " + lock_file.string());
  try {
    if (!fs::is_regular_file(dir / "depth.txt")) render_sequence(o.scenario, overrides, dir, true);
  } catch (...) {
    ::close(lock);
    throw;
  }
  ::close(lock);
  return dir;
}

// Runs the external mapper on the sequence; returns the directory it wrote its rasters to.
fs::path run_external(const ScoreOptions& o, const fs::path& sequence, const fs::path& out, int frames) {
  fs::create_directories(out);
  const json values{{"sequence", sequence.string()}, {"out", out.string()}, {"frames", std::to_string(frames)}};
  const std::vector<std::string> argv = substitute(split_command(o.command), values, o.command);
  if (!o.quiet) std::fprintf(stderr, "score: running %s\n", o.command.c_str());
  std::fflush(stdout);
  bool timed_out = false;
  const int status = run_program_with_timeout(argv, o.timeout, timed_out);
  throw_if_interrupted();
  if (status == -1) throw std::runtime_error("command '" + o.command + "': cannot start '" + argv[0] + "'");
  if (timed_out) throw std::runtime_error(fmt::format("command '{}': timed out after {} s", o.command, o.timeout));
  if (status != 0) throw std::runtime_error(fmt::format("command '{}': exited with status {}", o.command, status));
  if (!fs::is_regular_file(out / "circle.csv"))
    throw std::runtime_error("command '" + o.command + "' wrote no circle.csv into {out}");
  return out;
}

struct Estimates {
  RasterFrames circle, cylinder;  // cylinder.frames empty: no cylinder given
};

Estimates read_estimates(const fs::path& circle, const fs::path& cylinder, const RasterConfig& raster,
                         int frame_count) {
  Estimates e;
  e.circle = read_raster_frames(circle, 0, raster.azimuth_bins, frame_count);
  if (cylinder.empty()) return e;
  e.cylinder = read_raster_frames(cylinder, raster.rows(), raster.azimuth_bins, frame_count);
  for (const auto& [frame, cells] : e.cylinder.frames)
    if (!e.circle.frames.count(frame))
      throw InputError(cylinder.string(), 0, "frame", std::to_string(frame) + " is not in " + circle.string());
  for (const auto& [frame, cells] : e.circle.frames)
    if (!e.cylinder.frames.count(frame))
      throw InputError(cylinder.string(), 0, "frame", std::to_string(frame) + " of " + circle.string() + " is missing");
  return e;
}

// The config summary.json records (the raster and metric settings the scores depend on).
RunConfig score_config(const ScoreOptions& o, const RunSettings& s, int frames, std::uint64_t seed) {
  RunConfig c;
  c.mapper = o.name;
  c.raster = s.raster;
  c.metrics = s.metrics;
  c.frames = frames;
  c.seed = seed;
  c.overrides = o.overrides;
  c.command = o.command;
  return c;
}

// What scoring frame by frame gives the summary.
struct Scores {
  std::vector<eval::RasterMetrics> circle, cylinder;
};

// A program's circle has ranges only: put each known bin's point at its range along the bin's
// centre ray, so the picture shows where the program says the obstacles are.
void place_points(Circle& circle, const RasterOrigin& origin) {
  for (int k = 0; k < circle.size(); ++k) {
    RasterCell& c = circle.bins[k];
    if (!c.known()) continue;
    const double azimuth = origin.heading + circle.bin_centre_deg(k) * M_PI / 180.0;
    c.point = (origin.position + c.range * Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0.0)).cast<float>();
  }
}

bool pictured(const std::vector<int>& chosen, int frame, int last) {
  if (chosen.empty()) return frame == last;
  return std::find(chosen.begin(), chosen.end(), frame) != chosen.end();
}

// frames.csv, circle.csv and (with a cylinder given) cylinder.csv of a scored folder.
struct ScoreFiles {
  ResultFile frames, circle;
  std::optional<ResultFile> cylinder;
  ScoreFiles(const fs::path& dir, bool with_cylinder) : frames(dir / "frames.csv"), circle(dir / "circle.csv") {
    frames << frames_csv_header();
    circle << kCircleCsvHeader;
    if (with_cylinder) cylinder.emplace(dir / "cylinder.csv"), *cylinder << kCylinderCsvHeader;
  }
  void close() {
    frames.close();
    circle.close();
    if (cylinder) cylinder->close();
  }
};

// The chosen pictures of one scored frame: the circle beside the truth, and the cylinder.
void draw_frame(const fs::path& dir, const std::string& scene, const ScoreOptions& o, int i, double time,
                const Circle& circle, const Cylinder* cylinder, const eval::GroundTruthRasters& truth,
                const RasterOrigin& origin, const RasterConfig& raster) {
  const std::string stem = fmt::format("frame_{:06d}", i);
  plot_circle(dir / "pictures" / (stem + "_circle.png"), circle, &truth.circle, origin, raster,
              fmt::format("{}: {} circle, frame {} (t = {:.2f} s)", scene, o.name, i, time));
  if (cylinder)
    plot_cylinder(dir / "pictures" / (stem + "_cylinder.png"), *cylinder, raster,
                  fmt::format("{}: {} cylinder, frame {}", scene, o.name, i));
}

// Per frame of the estimates: the truth at the true pose, the metrics, frames.csv, the rasters
// beside the truth and the chosen pictures, in `dir`.
Scores score_frames(const Estimates& estimates, FrameSource& source, const RunSettings& settings,
                    const ScoreOptions& o, const fs::path& dir) {
  const bool with_cylinder = !estimates.cylinder.frames.empty();
  const int last = estimates.circle.frames.rbegin()->first;
  const bool pictures = !(o.picture_frames.size() == 1 && o.picture_frames[0] < 0);
  if (pictures) fs::create_directory(dir / "pictures");
  ScoreFiles files(dir, with_cylinder);
  Scores scores;
  Progress progress("score " + source.name(), static_cast<long>(estimates.circle.frames.size()), o.quiet);
  for (const auto& [i, cells] : estimates.circle.frames) {
    throw_if_interrupted();
    const SourceFrame sensed = source.frame(i);
    const RasterOrigin origin = raster_origin(sensed.world_T_body_true, source.ground_z());
    Circle circle(settings.raster.azimuth_bins);
    circle.bins = cells;
    place_points(circle, origin);
    Cylinder cylinder = make_cylinder(settings.raster);
    if (with_cylinder) cylinder.cells = estimates.cylinder.frames.at(i);
    // The evaluation `run` uses, without the EDF comparison (no map to trace in).
    const auto triangles = source.truth(sensed.frame.time);
    const eval::FrameEvaluation evaluation = eval::evaluate_frame(
        circle, cylinder, eval::FrameTruth{&*triangles, origin}, nullptr, origin,
        {settings.raster, settings.metrics, settings.edf});
    FrameRow row = FrameRow::of(i, sensed.frame.time, sensed.world_T_body_true, evaluation);
    if (!with_cylinder) row.cylinder.reset();
    files.frames << frames_csv_row(row);
    scores.circle.push_back(evaluation.circle);
    write_circle_rows(files.circle.stream(), i, circle, evaluation.truth.circle);
    if (with_cylinder) {
      scores.cylinder.push_back(evaluation.cylinder);
      write_cylinder_rows(files.cylinder->stream(), i, cylinder, evaluation.truth.cylinder);
    }
    if (pictures && pictured(o.picture_frames, i, last))
      draw_frame(dir, source.name(), o, i, sensed.frame.time, circle, with_cylinder ? &cylinder : nullptr,
                 evaluation.truth, origin, settings.raster);
    progress.update(static_cast<long>(scores.circle.size()));
  }
  progress.finish();
  files.close();
  return scores;
}

}  // namespace

RunSummary score_rasters(const ScoreOptions& o) {
  RunSettings settings;
  std::vector<std::string> scenario_overrides;
  split_overrides(o.overrides, scenario_overrides, settings);
  if (!settings.mapper.empty()) throw InputError("--set mapper.*: score runs no mapper");
  if (fs::is_directory(o.scenario))
    throw InputError(o.scenario.string() + ": score needs a scenario file (the ground truth comes from its geometry)");
  if (!(o.timeout > 0.0 && o.timeout <= 7 * 86400.0))
    throw InputError(fmt::format("--timeout must be in (0, 604800] seconds, got {}", o.timeout));
  std::unique_ptr<FrameSource> source = open_frame_source(o.scenario, scenario_overrides, o.frames, o.seed);
  const int frame_count = source->frame_count();

  std::vector<fs::path> inputs = source->inputs();
  inputs.insert(inputs.end(), {o.circle, o.cylinder, o.sequence_cache});
  StagedDirectory staged(o.out, "score", inputs);
  const fs::path dir = staged.path();
  fs::path circle_file = o.circle, cylinder_file = o.cylinder;
  if (!o.command.empty()) {
    const fs::path sequence = cached_sequence(o, scenario_overrides, source->name(), source->seed(), frame_count);
    const fs::path written = run_external(o, sequence, dir / "external", frame_count);
    circle_file = written / "circle.csv";
    cylinder_file = fs::is_regular_file(written / "cylinder.csv") ? written / "cylinder.csv" : fs::path();
  }
  const Estimates estimates = read_estimates(circle_file, cylinder_file, settings.raster, frame_count);
  const Scores scores = score_frames(estimates, *source, settings, o, dir);

  RunSummary summary;
  summary.scenario_name = source->name();
  summary.scenario_file = o.scenario.string();
  summary.seed = source->seed();
  summary.code_version = code_version();
  summary.ground_truth = true;
  summary.config = score_config(o, settings, frame_count, source->seed());
  summary.evaluated_frames = static_cast<int>(scores.circle.size());
  summary.tags = parse_tags(o.tags);
  const bool external = !o.command.empty();
  summary.scored = ScoredFiles{external ? "external/circle.csv" : o.circle.string(), std::nullopt};
  if (!cylinder_file.empty()) summary.scored->cylinder = external ? "external/cylinder.csv" : o.cylinder.string();
  summary.circle = RasterSummary::of(scores.circle);
  summary.cylinder = RasterSummary::of(scores.cylinder);
  write_result_file(dir / "summary.json", json(summary).dump(2) + "\n");
  staged.commit();
  return summary;
}

void add_score_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<ScoreOptions>();
  CLI::App* cmd = app.add_subcommand(
      "score", "Score rasters made by any program against the scenario's exact ground truth; writes "
               "a result directory like `run` (summary.json, frames.csv, circle.csv with truth, pictures)");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file the program saw")->required();
  cmd->add_option("--circle", o->circle, "Circle estimates: CSV frame,bin,estimate (empty = unknown)");
  cmd->add_option("--cylinder", o->cylinder, "Cylinder estimates: CSV frame,row,bin,estimate");
  cmd->add_option("--out", o->out, "Result directory (written atomically)")->required();
  cmd->add_option("--frames", o->frames, "Number of frames (default: the scenario's)")->check(CLI::PositiveNumber);
  cmd->add_option("--seed", o->seed, "Run seed (overrides the scenario's)");
  cmd->add_option("--set", o->overrides, "key=value: a scenario key or a raster.* / metrics.* run key");
  cmd->add_option("--name", o->name, "The program's name, recorded as the mapper");
  cmd->add_option("--pictures", o->picture_frames, "Frames to draw (default: the last scored; -1: none)");
  cmd->add_option("--tag", o->tags, "key=value label recorded in summary.json");
  cmd->add_option("--command", o->command,
                  "External mapper to run first (no shell): {sequence} (a TUM RGB-D directory), {out} "
                  "(where it writes circle.csv, optionally cylinder.csv), {frames}");
  cmd->add_option("--timeout", o->timeout, "Time limit of --command, seconds");
  cmd->add_option("--sequence-cache", o->sequence_cache,
                  "Where --command's rendered sequences are kept (default: beside --out)");
  cmd->callback([o, &global] {
    o->quiet = global.quiet;
    if (o->command.empty() == o->circle.empty())
      throw InputError("score: give either --circle (and optionally --cylinder) or --command");
    if (!o->command.empty() && o->sequence_cache.empty()) o->sequence_cache = o->out.parent_path() / "sequences";
    install_interrupt_handler();
    const RunSummary summary = score_rasters(*o);
    if (!global.quiet) {
      const MeanMetrics& m = summary.circle.mean;
      std::printf("score: %s, %d frames; circle mean coverage %s, mean RMSE %s m\n  results: %s\n",
                  summary.scenario_name.c_str(), summary.evaluated_frames, json(m.coverage).dump().c_str(),
                  json(m.rmse).dump().c_str(), o->out.string().c_str());
    }
  });
}

}  // namespace sonomap::harness
