// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/run.hpp"

#include "core/rasterise_map.hpp"
#include "core/rasteriser.hpp"
#include "core/stopwatch.hpp"
#include "eval/evaluate_frame.hpp"
#include "harness/app/frame_outputs.hpp"
#include "harness/app/listen_step.hpp"
#include "harness/app/run_results.hpp"
#include "harness/app/run_setup.hpp"
#include "harness/app/sonify.hpp"
#include "harness/app/video_maker.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// A step's complaint about a frame's data (a bad pose, a bad EDF setting) names the frame.
template <typename Step>
auto at_frame(const Frame& frame, Step&& step) {
  try {
    return step();
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("frame {} (t = {:.3f} s): {}", frame.index, frame.time, e.what()));
  }
}

// The sensor's frame i, and the truth that stays with the evaluator.
SourceFrame sense(FrameSource& source, int i, FrameTimes& times) {
  const auto t0 = StageClock::now();
  SourceFrame sensed = source.frame(i);
  times.emplace_back("render", ms_since(t0));
  return sensed;
}

void integrate(Mapper& mapper, const Frame& frame, FrameTimes& times) {
  const auto t0 = StageClock::now();
  at_frame(frame, [&] { mapper.integrate(frame); });
  times.emplace_back("integrate", ms_since(t0));
  for (const auto& stage : mapper.last_stage_times().stages)
    times.emplace_back("map." + stage.first, stage.second);
}

void rasterise(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
               RasterScratch& scratch, FrameTimes& times) {
  const auto t0 = StageClock::now();
  rasterise_map(mapper, origin, rasteriser, scratch);
  times.emplace_back("raster", ms_since(t0));
}

// Truth from the scene at the frame's time seen from the true pose (for recorded data: its
// reference cloud or mesh, if the sequence file names one).
eval::FrameEvaluation evaluate(const RunInputs& inputs, const Mapper& mapper,
                               const SourceFrame& sensed, const Rasteriser& rasteriser,
                               bool with_edf, FrameTimes& times) {
  const auto triangles = inputs.source->truth(sensed.frame.time);
  const auto* cloud = inputs.source->truth_cloud();
  std::optional<eval::FrameTruth> truth;
  if (triangles || cloud)
    truth = eval::FrameTruth{triangles ? &*triangles : nullptr,
                             raster_origin(sensed.world_T_body_true, inputs.source->ground_z()), cloud};
  const RunSettings& s = inputs.settings;
  eval::FrameEvaluation evaluation = at_frame(sensed.frame, [&] {
    return eval::evaluate_frame(rasteriser.circle(), rasteriser.cylinder(), truth,
                                with_edf ? &mapper : nullptr, rasteriser.origin(),
                                {s.raster, s.metrics, s.edf});
  });
  times.insert(times.end(), evaluation.times.begin(), evaluation.times.end());
  return evaluation;
}

// The tracker of moved objects' ghosts, for a source whose moving objects are known.
std::optional<eval::MovedGhosts> moved_ghosts_tracker(const RunInputs& inputs) {
  std::vector<eval::MovingObjectShape> objects = inputs.source->moving_objects();
  if (objects.empty()) return std::nullopt;
  const RunSettings& s = inputs.settings;
  return eval::MovedGhosts(std::move(objects), {s.metrics.ghost_tolerance, inputs.source->ground_z(), s.raster});
}

// The frame's readings of moved objects' old places, from the true poses (stage "moved_ghosts").
void track_moved_ghosts(eval::MovedGhosts& moved, const RunInputs& inputs, const SourceFrame& sensed,
                        const Rasteriser& rasteriser, eval::FrameEvaluation& evaluation, FrameTimes& times) {
  const auto t0 = StageClock::now();
  const Frame& f = sensed.frame;
  const Eigen::Isometry3d world_T_camera_true = sensed.world_T_body_true * f.world_T_body.inverse() * f.world_T_camera;
  evaluation.moved = at_frame(f, [&] {
    return moved.add_frame(f.index, inputs.source->moving_poses(f.time), rasteriser.circle(),
                           evaluation.truth.circle, f, world_T_camera_true);
  });
  times.emplace_back("moved_ghosts", ms_since(t0));
}

}  // namespace

RunOutcome run_scenario(const RunOptions& options) {
  RunInputs inputs = load_run_inputs(options);
  const std::unique_ptr<Mapper> mapper = build_mapper(options, inputs);
  FrameSource& source = *inputs.source;
  const FrameSchedule schedule(options, inputs.settings, source.frame_count());

  std::vector<fs::path> input_paths = source.inputs();
  input_paths.push_back(options.brir_dir.empty() ? default_hrir_file() : options.brir_dir);
  StagedDirectory staged(options.out, "run", input_paths);
  RunResults results(staged.path(), options.write_rasters);
  FrameOutputs outputs(staged.path(), options, schedule, source.name(), mapper->name(),
                       inputs.settings.raster);
  std::optional<ListenStep> listen;  // --listen: listen.wav, the stream over the whole run
  if (options.listen || options.video) listen.emplace(staged.path(), options, inputs.settings.listen, source.head());
  Rasteriser rasteriser(inputs.settings.raster);
  std::optional<RunVideo> video;
  if (options.video)
    video.emplace(staged.path(), source.name(), mapper->name(), inputs.settings.raster,
                  schedule.frame_count(),
                  SweepClock{inputs.settings.listen.stream.period_s, inputs.settings.listen.stream.pause_s, 36});
  std::optional<eval::MovedGhosts> moved = moved_ghosts_tracker(inputs);
  RasterScratch raster_scratch;
  std::vector<Eigen::Vector3f> surface;  // the band's samples, for the video's top view
  Progress progress("run " + source.name(), schedule.frame_count(), options.quiet);
  for (int i = 0; i < schedule.frame_count(); ++i) {
    throw_if_interrupted();
    FrameTimes times;
    const SourceFrame sensed = sense(source, i, times);
    integrate(*mapper, sensed.frame, times);
    if (schedule.evaluated(i)) {
      const RasterOrigin origin = raster_origin(sensed.frame.world_T_body, source.ground_z());
      rasterise(*mapper, origin, rasteriser, raster_scratch, times);
      if (video) band_samples(*mapper, origin, rasteriser.config(), surface);
      const bool with_edf = schedule.edf(i, results.evaluated_frames());
      eval::FrameEvaluation evaluation = evaluate(inputs, *mapper, sensed, rasteriser, with_edf, times);
      if (moved) track_moved_ghosts(*moved, inputs, sensed, rasteriser, evaluation, times);
      const FrameView view{i, sensed.frame.time, origin, &rasteriser.circle(),
                           &rasteriser.cylinder(), video ? &surface : nullptr, mapper.get(), &evaluation};
      results.add_frame(view, sensed.world_T_body_true, schedule.last(i));
      outputs.write(view);
      if (listen) listen->add(view);
      if (video) video->add_rasters(view);
    }
    if (video) video->add_frame(sensed.frame);
    results.add_timings(i, times);
    progress.update(i + 1);
  }
  progress.finish();

  RunSummary summary = describe_run(options, inputs, *mapper);
  results.fill_metrics(summary, inputs.settings.edf_enabled);
  if (moved) summary.moved_objects = moved->results();
  summary.sweeps = outputs.sweep_levels();
  if (listen) summary.listen = listen->finish(schedule.frame_count());
  if (video)  // the listening stream is the sound track (--video implies --listen)
    video->finish(std::optional<fs::path>(staged.path() / kListenWav));
  results.finish(summary, *mapper);
  staged.commit();
  return RunOutcome{options.out, summary};
}

std::string summary_screen(const RunOutcome& outcome) {
  const RunSummary& s = outcome.summary;
  auto cell = [](double v, const char* format) {
    return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : std::string("-");
  };
  auto final_cells = [&](const char* name, const RasterSummary& r) {
    const auto& f = r.final_frame;
    return fmt::format("  {:<10} {:>10} {:>10} {:>8}", name,
                       f ? cell(100.0 * f->coverage, "{:.1f}%") : "-",
                       f ? cell(f->rmse, "{:.3f} m") : "-", f ? std::to_string(f->ghosts) : "-");
  };
  auto row = [&](const char* name, const RasterSummary& r) {
    return final_cells(name, r) + fmt::format(" {:>12} {:>10}\n", cell(100.0 * r.mean.coverage, "{:.1f}%"),
                                              cell(r.mean.rmse, "{:.3f} m"));
  };
  std::string text = fmt::format("sonomap run: {} with {} ({} frames, seed {})\n", s.scenario_name,
                                 s.config.mapper, s.config.frames, s.seed);
  text += fmt::format("  {:<10} {:>10} {:>10} {:>8} {:>12} {:>10}\n", "raster", "coverage",
                      "RMSE", "ghosts", "mean cov.", "mean RMSE");
  text += row("circle", s.circle) + row("cylinder", s.cylinder);
  if (s.edf && s.edf->final_slip && s.edf_circle) {
    const SlipStats& slip = *s.edf->final_slip;
    text += final_cells("edf circle", *s.edf_circle) +
            fmt::format("   EDF bearing slip: median {}, p90 {}\n",
                        cell(slip.median_deg, "{:.1f} deg"), cell(slip.p90_deg, "{:.1f} deg"));
  }
  for (const eval::MovedObjectClearing& m : s.moved_objects) {
    if (!m.seen_empty_frame)
      text += fmt::format("  moved {}: old place never seen empty\n", m.name);
    else if (m.cleared())
      text += fmt::format("  moved {}: ghosts cleared {} frames after its old place was seen empty (frame {})\n",
                          m.name, *m.clearing_frames, *m.seen_empty_frame);
    else
      text += fmt::format("  moved {}: ghosts never cleared, {} bins left (old place seen empty at frame {})\n",
                          m.name, m.ghost_bins_at_end, *m.seen_empty_frame);
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
      ->check(CLI::Range(1, kMaxFrames));
  cmd->add_option("--every", options->every,
                  "Evaluate rasters, truth and metrics every K-th frame (and the last)")
      ->check(CLI::Range(1, kMaxFrames))->capture_default_str();
  cmd->add_option("--mapper", options->mapper,
                  "Mapper: vdb_gpdf, tsdf, open3d (Open3D's ScalableTSDFVolume) or depth_only")
      ->capture_default_str();
  cmd->add_option("--voxel", options->voxel, "Global voxel size in metres (default: the mapper's)")
      ->check(CLI::Range(kMinVoxel, kMaxVoxel));
  cmd->add_option("--seed", options->seed, "Run seed (overrides the scenario's)")
      ->check(CLI::Range(std::uint64_t{0}, kMaxSeed));
  cmd->add_option("--max-memory", options->max_memory_gib,
                  "Map memory budget in GiB; a voxel size whose estimated map needs more is "
                  "refused (0: half the RAM)")
      ->check(CLI::Range(0.0, 1e6))->capture_default_str();
  cmd->add_option("--set", options->overrides,
                  "key=value: override a scenario key or a run key (mapper.*, raster.*, metrics.*, edf.*, listen.*)");
  cmd->add_option("--pictures", options->picture_frames,
                  "Frames to draw (default: the last; -1: none)");
  cmd->add_option("--sweeps", options->sweep_frames,
                  "Frames to sonify as a WAV sweep (default: the last; -1: none)");
  cmd->add_option("--brir", options->brir_dir,
                  "BRIR directory for the sweeps (default: synthesise the room from the map)");
  cmd->add_flag("--listen", options->listen,
                "Write listen.wav: the binaural stream a wearer hears over the whole run, sweeps "
                "every listen.period (docs/sonification.md)");
  cmd->add_option("--tag", options->tags, "key=value label recorded in summary.json");
  cmd->add_flag("--video", options->video,
                 "Write run.mp4 (needs the ffmpeg program): depth image, circle with the sector\n"
                 "being played, map from above with the path, time and metrics, per frame; its sound\n"
                 "track is listen.wav (implies --listen)");
  cmd->add_flag("!--no-rasters", options->write_rasters, "Do not write circle.csv / cylinder.csv");
  cmd->footer(run_keys_help());
  cmd->callback([options, &global] {
    options->quiet = global.quiet;
    install_interrupt_handler();
    const RunOutcome outcome = run_scenario(*options);
    if (!global.quiet) std::fputs(summary_screen(outcome).c_str(), stdout);
  });
}

}  // namespace sonomap::harness
