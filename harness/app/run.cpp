// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/run.hpp"

#include "harness/app/frame_source.hpp"
#include "harness/app/result_files.hpp"
#include "harness/app/run_settings.hpp"

#include "core/edf_raster.hpp"
#include "core/rasteriser.hpp"
#include "core/stopwatch.hpp"
#include "eval/ground_truth.hpp"
#include "eval/metrics.hpp"
#include "harness/app/mapper_factory.hpp"
#include "harness/app/sonify.hpp"
#include "harness/formats/mesh_io.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/sofa_io.hpp"
#include "harness/formats/tum_io.hpp"
#include "harness/report/pictures.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"
#include "sim/simulation.hpp"
#include "sim/world_geometry.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

namespace fs = std::filesystem;
using nlohmann::json;

namespace sonomap::harness {
namespace {

using eval::GroundTruthRasters;
using eval::MetricsConfig;
using eval::RasterMetrics;

using Clock = StageClock;

std::string csv_number(double v) { return std::isfinite(v) ? fmt::format("{:.6f}", v) : ""; }

json slip_json(const SlipStats& s) {
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return json{{"median_deg", num(s.median_deg)}, {"p90_deg", num(s.p90_deg)}, {"observed", s.observed}};
}

// Per bin of the final frame: the map's circle next to the EDF's (edf.csv, README.md).
void write_edf_csv(const fs::path& file, int frame, const Circle& map_circle, const EdfRaster& edf,
                   const Circle& truth, double ground_z) {
  std::ofstream out(file);
  out << "frame,bin,azimuth_deg,map_range,edf_distance,slip_deg,traced_range,traced_height,truth,"
         "trace_end\n";
  for (int k = 0; k < map_circle.size(); ++k) {
    const EdfBin& b = edf.bins[k];
    out << frame << ',' << k << ',' << fmt::format("{:.4f}", map_circle.bin_centre_deg(k)) << ','
        << csv_range(map_circle.bins[k]) << ',' << csv_number(b.sample_distance) << ','
        << csv_number(b.slip_deg) << ',' << csv_range(edf.traced.bins[k]) << ','
        << csv_number(edf.traced.bins[k].point.z() - ground_z) << ',' << csv_range(truth.bins[k])
        << ',' << trace_end_name(b.end) << '\n';
  }
  close_checked(out, file);
}

bool chosen(const std::vector<int>& list, int frame, int last_evaluated) {
  if (list.empty()) return frame == last_evaluated;
  return std::find(list.begin(), list.end(), frame) != list.end();
}

// The sweep renderer, made at the first sweep: BRIRs from --brir, or synthesised for a shoebox
// room that is the bounding box of the map around the listener (at least 2 x 2 x 2.4 m).
class SweepMaker {
 public:
  SweepMaker(fs::path brir_dir, bool quiet) : brir_dir_(std::move(brir_dir)), quiet_(quiet) {}

  void write(const Circle& circle, const std::vector<Eigen::Vector3f>& map_points,
             const RasterOrigin& origin, const fs::path& wav, const fs::path& dir) {
    if (!renderer_) {
      SonifySetup setup;
      std::shared_ptr<const audio::BrirSet> brirs;
      if (!brir_dir_.empty()) {
        setup.brir_dir = brir_dir_;
        brirs = load_brirs(setup, quiet_);
      } else {
        Eigen::Vector3d lo = origin.position, hi = origin.position;
        for (const auto& p : map_points) {
          lo = lo.cwiseMin(p.cast<double>());
          hi = hi.cwiseMax(p.cast<double>());
        }
        lo.z() = std::min(lo.z(), origin.ground_z);
        const Eigen::Vector3d min_size(2.0, 2.0, 2.4), centre = 0.5 * (lo + hi);
        lo = lo.cwiseMin(centre - 0.5 * min_size);
        hi = hi.cwiseMax(centre + 0.5 * min_size);
        // The listener must stand inside, off the walls.
        lo = lo.cwiseMin(origin.position - Eigen::Vector3d::Constant(0.3));
        hi = hi.cwiseMax(origin.position + Eigen::Vector3d::Constant(0.3));
        audio::BrirSynthConfig room = room_from_box(lo, hi, origin.position, setup.room.rt60);
        room.listener_heading_deg = origin.heading * 180.0 / M_PI;
        room.max_order = setup.room.order;
        brirs = std::make_shared<const audio::BrirSet>(
            synthesize_brirs(room, setup.room.hrir_file, true));
        const json room_json{{"min_corner", {lo.x(), lo.y(), lo.z()}},
                             {"max_corner", {hi.x(), hi.y(), hi.z()}},
                             {"listener", {origin.position.x(), origin.position.y(), origin.position.z()}},
                             {"listener_heading_deg", room.listener_heading_deg},
                             {"rt60", room.rt60}, {"max_order", room.max_order},
                             {"hrir", setup.room.hrir_file.string()}};
        write_text_file(dir / "room.json", room_json.dump(2) + "\n");
      }
      renderer_ = std::make_unique<audio::SweepRenderer>(brirs, setup.sweep);
    }
    const audio::SweepAudio audio = renderer_->render(circle);
    write_sweep(audio, wav);
    levels_.push_back({{"file", wav.filename().string()}, {"gain_db", audio.gain_db},
                       {"loudness_lufs", audio.loudness.integrated_lufs},
                       {"true_peak_dbtp", audio.loudness.true_peak_dbtp},
                       {"peak_limited", audio.peak_limited}});
  }
  // Per sweep written: the one gain applied and the measured loudness (summary.json "sweeps").
  const json& levels() const { return levels_; }

 private:
  fs::path brir_dir_;
  bool quiet_;
  std::unique_ptr<audio::SweepRenderer> renderer_;
  json levels_ = json::array();
};

}  // namespace

void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   std::vector<Eigen::Vector3f>& surface) {
  surface.clear();
  mapper.surface_points(origin.position, rasteriser.config().max_range, surface);
  rasteriser.reset(origin);
  rasteriser.add(surface);
}

RunOutcome run_scenario(const RunOptions& options) {
  if (options.frames < 0) throw InputError("--frames must be positive, got " + std::to_string(options.frames));
  if (options.every < 1) throw InputError("--every must be at least 1, got " + std::to_string(options.every));

  const json tags = tags_json(options.tags);
  RunSettings settings;
  std::vector<std::string> scenario_overrides;
  split_overrides(options.overrides, scenario_overrides, settings);
  std::unique_ptr<FrameSource> source =
      open_frame_source(options.scenario, std::move(scenario_overrides), options.frames, options.seed);
  const bool has_truth = source->truth(0.0).has_value();

  auto mapper = make_mapper(options.mapper, options.voxel, settings.mapper);
  if (!settings.ghost_tolerance_set) {
    // docs/conventions.md: a ghost is more than 2 voxels closer than the truth.
    for (const auto& [key, value] : mapper->config_entries())
      if (key == "global_voxel" || key == "voxel") settings.metrics.ghost_tolerance = 2.0 * std::stod(value);
  }

  std::vector<fs::path> inputs = source->inputs();
  inputs.push_back(options.brir_dir.empty() ? default_hrir_file() : options.brir_dir);
  StagedDirectory staged(options.out, "run", inputs);
  const fs::path dir = staged.path();
  const auto wants = [](const std::vector<int>& frames) {
    return frames.empty() || std::any_of(frames.begin(), frames.end(), [](int f) { return f >= 0; });
  };
  if (wants(options.picture_frames)) fs::create_directory(dir / "pictures");
  if (wants(options.sweep_frames)) fs::create_directory(dir / "sweeps");

  std::ofstream frames_csv(dir / "frames.csv"), timings_csv(dir / "timings.csv");
  std::ofstream circle_csv, cylinder_csv;
  frames_csv << frames_csv_header();
  if (options.write_rasters) {
    circle_csv.open(dir / "circle.csv");
    cylinder_csv.open(dir / "cylinder.csv");
    circle_csv << "frame,bin,estimate,truth\n";
    cylinder_csv << "frame,row,bin,estimate,truth\n";
  }

  const int frame_count = source->frame_count();
  const int last_evaluated = frame_count - 1;
  Rasteriser rasteriser(settings.raster);
  std::vector<Eigen::Vector3f> surface;
  std::vector<RasterMetrics> circle_series, cylinder_series, edf_series;
  std::vector<SlipStats> slip_series;
  int evaluated = 0;
  std::vector<std::string> timing_columns;
  std::map<std::string, std::vector<double>> timing_samples;
  SweepMaker sweeps(options.brir_dir, options.quiet);
  Progress progress("run " + source->name(), frame_count, options.quiet);

  for (int i = 0; i < frame_count; ++i) {
    throw_if_interrupted();
    std::vector<std::pair<std::string, double>> times;
    auto t0 = Clock::now();
    const Frame frame = source->frame(i);
    times.emplace_back("render", ms_since(t0));

    t0 = Clock::now();
    try {
      mapper->integrate(frame);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("frame {} (t = {:.3f} s): {}", i, frame.time, e.what()));
    }
    times.emplace_back("integrate", ms_since(t0));
    for (const auto& stage : mapper->last_stage_times().stages)
      times.emplace_back("map." + stage.first, stage.second);

    const bool evaluate = (i % options.every == 0) || i == last_evaluated;
    if (evaluate) {
      t0 = Clock::now();
      const RasterOrigin origin = raster_origin(frame.world_T_body, source->ground_z());
      rasterise_map(*mapper, origin, rasteriser, surface);
      times.emplace_back("raster", ms_since(t0));

      // Without ground truth (recorded data) the truth rasters stay unknown and no metric is
      // computed: the metric columns are left empty.
      GroundTruthRasters truth{make_circle(settings.raster), make_cylinder(settings.raster)};
      RasterMetrics mc, my;
      mc.coverage = mc.rmse = my.coverage = my.rmse = NAN;
      mc.estimate_known = rasteriser.circle().known_count();
      my.estimate_known = rasteriser.cylinder().known_count();
      if (has_truth) {
        t0 = Clock::now();
        const RasterOrigin true_origin = raster_origin(frame.world_T_body_true, source->ground_z());
        truth = eval::ground_truth_rasters(*source->truth(frame.time), true_origin, settings.raster);
        times.emplace_back("truth", ms_since(t0));
        mc = eval::compare(rasteriser.circle(), truth.circle, settings.metrics);
        my = eval::compare(rasteriser.cylinder(), truth.cylinder, settings.metrics);
        circle_series.push_back(mc);
        cylinder_series.push_back(my);
      }
      // The EDF comparison (edf.*): every edf.every-th evaluated frame, the last and the
      // pictured ones. A mapper without a field gets an all-unknown EDF circle, not a guess.
      const bool picture = chosen(options.picture_frames, i, last_evaluated);
      std::optional<EdfRaster> edf;
      RasterMetrics me;
      SlipStats slip;
      if (settings.edf_enabled &&
          (evaluated % settings.edf_every == 0 || i == last_evaluated || picture)) {
        t0 = Clock::now();
        try {
          edf = edf_raster(*mapper, origin, settings.raster.azimuth_bins, settings.edf);
        } catch (const std::invalid_argument& e) {
          throw InputError(fmt::format("frame {} (t = {:.3f} s): {}", i, frame.time, e.what()));
        }
        times.emplace_back("edf", ms_since(t0));
        slip = slip_stats(*edf);
        slip_series.push_back(slip);
        me.coverage = me.rmse = me.rmse_off_edges = NAN;
        me.estimate_known = edf->traced.known_count();
        if (has_truth) {
          me = eval::compare(edf->traced, truth.circle, settings.metrics);
          edf_series.push_back(me);
        }
        if (i == last_evaluated)
          write_edf_csv(dir / "edf.csv", i, rasteriser.circle(), *edf, truth.circle, origin.ground_z);
      }
      ++evaluated;
      frames_csv << i << ',' << fmt::format("{:.6f}", frame.time) << ','
                 << pose_csv(frame.world_T_body_true);
      for (const RasterMetrics* m : {&mc, &my})
        frames_csv << ',' << csv_number(m->coverage) << ',' << csv_number(m->rmse) << ','
                   << csv_number(m->rmse_off_edges) << ','
                   << (has_truth ? std::to_string(m->ghosts) : "") << ',' << m->estimate_known;
      if (edf)
        frames_csv << ',' << csv_number(me.coverage) << ',' << csv_number(me.rmse) << ','
                   << csv_number(me.rmse_off_edges) << ','
                   << (has_truth ? std::to_string(me.ghosts) : "") << ',' << me.estimate_known
                   << ',' << csv_number(slip.median_deg) << ',' << csv_number(slip.p90_deg) << ','
                   << slip.observed;
      else
        frames_csv << ",,,,,,,,";
      frames_csv << '\n';

      if (options.write_rasters) {
        write_circle_rows(circle_csv, i, rasteriser.circle(), truth.circle);
        write_cylinder_rows(cylinder_csv, i, rasteriser.cylinder(), truth.cylinder);
      }
      if (chosen(options.picture_frames, i, last_evaluated)) {
        const std::string stem = fmt::format("frame_{:06d}", i);
        plot_circle(dir / "pictures" / (stem + "_circle.png"), rasteriser.circle(),
                    has_truth ? &truth.circle : nullptr,
                    origin, settings.raster,
                    fmt::format("{}: {} circle, frame {} (t = {:.2f} s)", source->name(),
                                mapper->name(), i, frame.time));
        plot_cylinder(dir / "pictures" / (stem + "_cylinder.png"), rasteriser.cylinder(),
                      settings.raster,
                      fmt::format("{}: {} cylinder, frame {}", source->name(), mapper->name(), i));
        if (edf)
          plot_edf_arrows(dir / "pictures" / (stem + "_edf.png"), rasteriser.circle(), *edf, origin,
                          settings.raster,
                          fmt::format("{}: {} circle vs EDF, frame {} (slip median {:.1f} deg)",
                                      source->name(), mapper->name(), i, slip.median_deg));
      }
      if (chosen(options.sweep_frames, i, last_evaluated))
        sweeps.write(rasteriser.circle(), surface, origin,
                     dir / "sweeps" / fmt::format("frame_{:06d}.wav", i), dir / "sweeps");
    }

    if (timing_columns.empty()) {
      for (const auto& t : times) timing_columns.push_back(t.first);
      timings_csv << "frame";
      for (const auto& name : timing_columns) timings_csv << ',' << name << "_ms";
      timings_csv << '\n';
    }
    timings_csv << i;
    for (const auto& name : timing_columns) {
      auto it = std::find_if(times.begin(), times.end(), [&](auto& t) { return t.first == name; });
      timings_csv << ',' << (it != times.end() ? fmt::format("{:.3f}", it->second) : "");
      if (it != times.end()) timing_samples[name].push_back(it->second);
    }
    timings_csv << '\n';
    progress.update(i + 1);
  }
  progress.finish();

  json config{{"mapper", mapper->name()}, {"mapper_config", json::object()},
              {"raster", {{"azimuth_bins", settings.raster.azimuth_bins},
                          {"band_min", settings.raster.band_min},
                          {"band_max", settings.raster.band_max},
                          {"row_height", settings.raster.row_height},
                          {"max_range", settings.raster.max_range}}},
              {"metrics", {{"ghost_tolerance", settings.metrics.ghost_tolerance},
                           {"edge_jump", settings.metrics.edge_jump}}},
              {"edf", {{"enabled", settings.edf_enabled}, {"every", settings.edf_every},
                       {"sample_radius", settings.edf.sample_radius},
                       {"hit_tolerance", settings.edf.hit_tolerance},
                       {"max_steps", settings.edf.max_steps},
                       {"max_range", settings.edf.max_range},
                       {"trace_rows", settings.edf_trace_rows},
                       {"trace_heights", settings.edf.trace_heights}}},
              {"frames", frame_count}, {"every", options.every}, {"seed", source->seed()},
              {"overrides", options.overrides}};
  for (const auto& [key, value] : mapper->config_entries()) config["mapper_config"][key] = value;

  json summary{{"scenario", {{"name", source->name()}, {"file", options.scenario.string()}}},
               {"sweeps", sweeps.levels()},
               {"seed", source->seed()},
               {"code_version", code_version()},
               {"ground_truth", has_truth},
               {"ground_truth_note", has_truth ? "exact wedge minima from the scenario's geometry"
                                               : "recorded data: no ground truth, no metrics"},
               {"config", config},
               {"config_hash", config_hash(config)},
               {"evaluated_frames", evaluated},
               {"tags", tags},
               {"metrics", {{"circle", metrics_summary(circle_series)},
                            {"cylinder", metrics_summary(cylinder_series)}}}};
  if (settings.edf_enabled) {
    // The EDF circle's metrics sit beside the map's; the slip (no truth needed) in "edf".
    summary["metrics"]["edf_circle"] = metrics_summary(edf_series);
    double median = 0.0, p90 = 0.0;
    int n = 0;
    for (const SlipStats& s : slip_series)
      if (s.observed > 0) median += s.median_deg, p90 += s.p90_deg, ++n;
    summary["edf"] = {{"frames", slip_series.size()},
                      {"slip", {{"final", slip_series.empty() ? json(nullptr) : slip_json(slip_series.back())},
                                {"mean", {{"median_deg", n ? json(median / n) : json(nullptr)},
                                          {"p90_deg", n ? json(p90 / n) : json(nullptr)}}}}}};
  }

  json timings = json::object();
  for (auto& [name, samples] : timing_samples) {
    std::sort(samples.begin(), samples.end());
    timings[name] = {{"median_ms", samples[samples.size() / 2]}, {"samples", samples.size()}};
  }

  close_checked(frames_csv, dir / "frames.csv");
  close_checked(timings_csv, dir / "timings.csv");
  close_checked(circle_csv, dir / "circle.csv");
  close_checked(cylinder_csv, dir / "cylinder.csv");
  {
    std::vector<Eigen::Vector3f> vertices;
    std::vector<Eigen::Vector3i> triangles;
    mapper->surface_mesh(vertices, triangles);
    if (!triangles.empty()) save_mesh_ply(dir / "map.ply", vertices, triangles);
  }
  write_text_file(dir / "summary.json", summary.dump(2) + "\n");
  write_text_file(dir / "timings.json", timings.dump(2) + "\n");
  staged.commit();
  return RunOutcome{options.out, summary};
}

std::string summary_screen(const RunOutcome& outcome) {
  const json& s = outcome.summary;
  auto metric = [&](const char* raster, const char* which, const char* name) -> std::string {
    const json& v = s["metrics"][raster][which];
    if (v.is_null() || v[name].is_null()) return "-";
    if (std::string(name) == "coverage") return fmt::format("{:.1f}%", 100.0 * v[name].get<double>());
    if (std::string(name) == "rmse") return fmt::format("{:.3f} m", v[name].get<double>());
    return fmt::format("{}", v[name].dump());
  };
  std::string text = fmt::format("sonomap run: {} with {} ({} frames, seed {})\n",
                                 s["scenario"]["name"].get<std::string>(),
                                 s["config"]["mapper"].get<std::string>(),
                                 s["config"]["frames"].get<int>(), s["seed"].get<std::uint64_t>());
  text += fmt::format("  {:<10} {:>10} {:>10} {:>8} {:>12} {:>10}\n", "raster", "coverage",
                      "RMSE", "ghosts", "mean cov.", "mean RMSE");
  for (const char* raster : {"circle", "cylinder"})
    text += fmt::format("  {:<10} {:>10} {:>10} {:>8} {:>12} {:>10}\n", raster,
                        metric(raster, "final", "coverage"), metric(raster, "final", "rmse"),
                        metric(raster, "final", "ghosts"), metric(raster, "mean", "coverage"),
                        metric(raster, "mean", "rmse"));
  if (s.contains("edf") && !s["edf"]["slip"]["final"].is_null()) {
    const json& slip = s["edf"]["slip"]["final"];
    auto deg = [](const json& v) { return v.is_null() ? std::string("-") : fmt::format("{:.1f} deg", v.get<double>()); };
    text += fmt::format("  {:<10} {:>10} {:>10} {:>8}   EDF bearing slip: median {}, p90 {}\n",
                        "edf circle", metric("edf_circle", "final", "coverage"),
                        metric("edf_circle", "final", "rmse"), metric("edf_circle", "final", "ghosts"),
                        deg(slip["median_deg"]), deg(slip["p90_deg"]));
  }
  text += fmt::format("  results: {}\n", outcome.dir.string());
  return text;
}

void add_run_command(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run a scenario through the whole chain (sensor, mapper, rasters, ground truth, "
             "metrics, pictures, sweeps) and write one result directory");
  cmd->add_option("scenario", options->scenario,
                  "Scenario YAML file, a recorded TUM RGB-D directory (depth.txt, groundtruth.txt,\n"
                  "depth/*.png, camera.yaml), or a sequence file (sequence.yaml: a folder of depth\n"
                  "PNGs or a ROS1 bag; docs/real-data.md). Recordings: no ground truth, no metrics")->required();
  cmd->add_option("--out", options->out,
                  "Result directory (written atomically): new, empty, or an earlier sonomap result")
      ->required();
  cmd->add_option("--frames", options->frames, "Number of frames (default: the scenario's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--every", options->every,
                  "Evaluate rasters, truth and metrics every K-th frame (and the last)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--mapper", options->mapper, "Mapper: vdb_gpdf, tsdf or depth_only")
      ->capture_default_str();
  cmd->add_option("--voxel", options->voxel, "Global voxel size in metres (default: the mapper's)");
  cmd->add_option("--seed", options->seed, "Run seed (overrides the scenario's)");
  cmd->add_option("--set", options->overrides,
                  "key=value: override a scenario key or a run key (mapper.*, raster.*, metrics.*, edf.*)");
  cmd->add_option("--pictures", options->picture_frames,
                  "Frames to draw (default: the last; -1: none)");
  cmd->add_option("--sweeps", options->sweep_frames,
                  "Frames to sonify as a WAV sweep (default: the last; -1: none)");
  cmd->add_option("--brir", options->brir_dir,
                  "BRIR directory for the sweeps (default: synthesise the room from the map)");
  cmd->add_option("--tag", options->tags, "key=value label recorded in summary.json");
  cmd->add_flag("!--no-rasters", options->write_rasters, "Do not write circle.csv / cylinder.csv");
  cmd->callback([options, &global] {
    options->quiet = global.quiet;
    install_interrupt_handler();
    const RunOutcome outcome = run_scenario(*options);
    if (!global.quiet) std::fputs(summary_screen(outcome).c_str(), stdout);
  });
}

}  // namespace sonomap::harness
