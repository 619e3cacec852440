// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap bench map`: median time per frame of each mapping stage (VDB-GPDF: local GPs, query
// points, fusion, G-GPDF; every mapper: the circle and cylinder rasters) at several voxel sizes
// and thread counts, against Open3D's ScalableTSDFVolume integrating the same frames in the same
// process. The machine is shared and noisy: what counts are medians and the ratios to the
// reference measured alongside, not single absolute times.
#include "harness/app/bench.hpp"

#include "core/rasteriser.hpp"
#include "core/stopwatch.hpp"
#include "core/tsdf.hpp"
#include "core/vector_isa.hpp"
#include "harness/app/mapper_factory.hpp"
#include "core/rasterise_map.hpp"
#include "harness/formats/modules.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"
#include "sim/cloud_frame.hpp"
#include "sim/simulation.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <omp.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::harness {

namespace {

using nlohmann::json;

// The reference: the `open3d` mapper (Open3D's ScalableTSDFVolume, with the TSDF peer's voxel
// and truncation), run like every other mapper; its ratios use its fusion time ("map").
constexpr const char* kOpen3d = "open3d";
constexpr int kMaxWarmup = 1000;
const TsdfConfig kPeer;  // the open3d mapper's defaults (voxel, truncation, ranges) are the TSDF peer's

struct BenchMapOptions {
  std::string scenario = "scenes/room.yaml";
  int frames = 60;
  // Room: the listener turns once in 30 s (900 frames), so 60 frames 15 apart see every side.
  int every = 15;
  // Frames integrated untimed before each (voxel, threads) group (warm_up).
  int warmup = 10;
  std::vector<double> voxels{0.05, 0.10, 0.15};
  std::vector<int> threads{1, 2};
  std::vector<std::string> mappers{"vdb_gpdf", "tsdf", kOpen3d};
  // What the mappers get: the depth image and its points ("image"), or the points alone
  // ("cloud"), of every row_step-th image row only when row_step > 1 (a lidar's rings).
  std::string input = "image";
  int row_step = 1;
  std::string json;
};

// Stage name and wall time in ms, in the order the stages ran.
using StageList = std::vector<std::pair<std::string, double>>;

// A mapper under test, followed by the circle and cylinder exactly as `run` builds them. It
// reports its own stages, "map" (the whole fusion), "raster" and "frame" (map + raster).
class TimedMap {
 public:
  TimedMap(std::unique_ptr<Mapper> mapper, double ground_z)
      : mapper_(std::move(mapper)), ground_z_(ground_z) {}

  void process(const Frame& frame, StageList& stages) {
    auto t0 = StageClock::now();
    mapper_->integrate(frame);
    const double map_ms = ms_since(t0);
    for (const auto& stage : mapper_->last_stage_times().stages)
      if (stage.first != "total") stages.push_back(stage);
    t0 = StageClock::now();
    rasterise_map(*mapper_, raster_origin(frame.world_T_body, ground_z_), rasteriser_, raster_scratch_);
    const double raster_ms = ms_since(t0);
    stages.emplace_back("raster", raster_ms);
    stages.emplace_back("map", map_ms);
    stages.emplace_back("frame", map_ms + raster_ms);
  }
  const Mapper& mapper() const { return *mapper_; }

 private:
  std::unique_ptr<Mapper> mapper_;
  double ground_z_;
  Rasteriser rasteriser_;
  RasterScratch raster_scratch_;
};

// One (voxel, threads, mapper) cell: per-frame samples of every stage.
struct CellResult {
  double voxel = 0.0;
  int threads = 0;
  std::string mapper;
  std::vector<std::string> stage_order;  // as the stages ran in the first frame
  std::map<std::string, std::vector<double>> samples;
  std::vector<double> frame_cpu_ms;  // process CPU time of the whole frame (all threads)
  size_t peak_map_bytes = 0;
  // Ratios to the reference's fusion: median frame (or map) / Open3D's median map in the same cell.
  double frame_ratio = NAN;
  double map_ratio = NAN;

  double median_of(const std::string& stage) const { return median(samples.at(stage)); }
};

// Open3D's mesh against our TSDF's surface samples, integrated from the same frames.
struct ReferenceCheck {
  double voxel = 0.0;
  int threads = 0;
  size_t open3d_vertices = 0;
  size_t tsdf_samples = 0;
  double median_distance = NAN;  // m, Open3D vertex to the nearest TSDF sample
  // A reference that is not where our TSDF is (wrong pose or axes) makes every ratio void.
  bool passed() const { return open3d_vertices > 0 && median_distance < voxel; }
};

double median_nearest_distance(const std::vector<Eigen::Vector3f>& from,
                               const std::vector<Eigen::Vector3f>& to) {
  std::vector<double> distances = open3d_functions().nearest_distances(from, to);
  return distances.empty() ? NAN : median(std::move(distances));
}

// The input, as printed and written: what the mappers were given, and its points per frame.
struct InputSummary {
  std::string text;
  double median_points = 0.0;
  double row_spacing_deg = NAN;  // cloud rows, at the image's centre
};
InputSummary summarise_input(const BenchMapOptions& o, const sim::Scenario& scenario, const std::vector<Frame>& frames) {
  std::vector<double> points;
  for (const Frame& f : frames) points.push_back(static_cast<double>(f.points_camera.size()));
  InputSummary s{"", points.empty() ? 0.0 : median(points)};
  if (o.input == "image") {
    s.text = fmt::format("depth images and their points ({:.0f} points a frame)", s.median_points);
    return s;
  }
  s.row_spacing_deg = std::atan(o.row_step / scenario.camera.fy) * 180.0 / M_PI;
  s.text = o.row_step == 1 ? fmt::format("points only ({:.0f} a frame)", s.median_points)
                           : fmt::format("points of every {}-th image row only, {:.2f} degrees apart ({:.0f} a frame)",
                                         o.row_step, s.row_spacing_deg, s.median_points);
  return s;
}

// The OpenMP runtime reads OMP_WAIT_POLICY once, when it loads: record what it was.
const char* omp_wait_policy() { return std::getenv("OMP_WAIT_POLICY"); }

double process_peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports KiB
}

constexpr int kMaxRowStep = 100000;

void check_options(const BenchMapOptions& o) {
  if (o.frames < 1) throw InputError("--frames must be at least 1, got " + std::to_string(o.frames));
  if (o.every < 1) throw InputError("--every must be at least 1, got " + std::to_string(o.every));
  if (o.warmup < 0 || o.warmup > kMaxWarmup)
    throw InputError(fmt::format("--warmup must be in [0, {}], got {}", kMaxWarmup, o.warmup));
  if (o.voxels.empty() || o.threads.empty() || o.mappers.empty())
    throw InputError("--voxels, --threads-list and --mappers each need at least one value");
  for (double v : o.voxels)
    if (!(v > 0.0) || !std::isfinite(v))
      throw InputError(fmt::format("--voxels: a voxel size must be a positive length in metres, got {}", v));
  for (int t : o.threads)
    if (t < 1) throw InputError(fmt::format("--threads-list: a thread count must be at least 1, got {}", t));
  for (const std::string& m : o.mappers) {
    const auto names = mapper_names();
    if (std::find(names.begin(), names.end(), m) == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw InputError("--mappers " + m + ": unknown mapper (known: " + known + ")");
    }
  }
  if (o.row_step < 1 || o.row_step > kMaxRowStep)
    throw InputError(fmt::format("--row-step must be in [1, {}], got {}", kMaxRowStep, o.row_step));
  if (o.row_step > 1 && o.input != "cloud")
    throw InputError("--row-step " + std::to_string(o.row_step) + " thins a cloud: give --input cloud");
  if (o.input == "cloud" && std::find(o.mappers.begin(), o.mappers.end(), kOpen3d) != o.mappers.end())
    throw InputError("--mappers open3d: Open3D's TSDF fuses depth images, and --input cloud gives "
                     "points only (leave open3d out, or bench --input image)");
  if (!o.json.empty()) {
    const std::filesystem::path parent = std::filesystem::path(o.json).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent))
      throw InputError("--json " + o.json + ": the directory " + parent.string() + " does not exist");
    check_output_file(o.json, is_sonomap_json, {o.scenario});
  }
}

// Frames 0, every, 2 every, ... (at most `frames` of them), rendered once: never timed.
std::vector<Frame> render_frames(const sim::Scenario& scenario, const BenchMapOptions& o,
                                 Progress& progress, long& done) {
  sim::Simulation simulation(scenario);
  std::vector<Frame> frames;
  for (long i = 0; i < o.frames && i * o.every < simulation.frame_count(); ++i) {
    frames.push_back(simulation.render(static_cast<int>(i * o.every)));
    if (o.input == "cloud") sim::keep_cloud(frames.back(), o.row_step);
    progress.update(++done);
  }
  return frames;
}

// The Open3D reference check of a (voxel, threads) group, once every mapper has seen the frames.
std::optional<ReferenceCheck> reference_check(const std::vector<Frame>& frames, const sim::Scenario& scenario,
                                              double voxel, int threads,
                                              const std::vector<std::pair<std::string, TimedMap*>>& maps) {
  std::vector<Eigen::Vector3f> tsdf_surface, open3d_vertices;
  for (const auto& [name, map] : maps) {
    if (name == "tsdf") {
      // Everything the camera reached: within its range of any camera position (the surface
      // query's cost grows with the area of the radius, so no "infinite" radius).
      const Eigen::Vector3d centre = frames.front().world_T_camera.translation();
      double reach = 0.0;
      for (const Frame& f : frames) reach = std::max(reach, (f.world_T_camera.translation() - centre).norm());
      map->mapper().surface_points(centre, reach + scenario.camera.max_range + 1.0, tsdf_surface);
    } else if (name == kOpen3d) {
      std::vector<Eigen::Vector3i> triangles;
      map->mapper().surface_mesh(open3d_vertices, triangles);
    }
  }
  if (tsdf_surface.empty() || open3d_vertices.empty()) return std::nullopt;
  return ReferenceCheck{voxel, threads, open3d_vertices.size(), tsdf_surface.size(),
                        median_nearest_distance(open3d_vertices, tsdf_surface)};
}

std::vector<std::unique_ptr<TimedMap>> make_maps(const std::vector<std::string>& mappers, double voxel,
                                                 const sim::Scenario& scenario) {
  std::vector<std::unique_ptr<TimedMap>> maps;
  for (const std::string& name : mappers)
    maps.push_back(std::make_unique<TimedMap>(make_mapper(name, voxel, {}), scenario.ground_z));
  return maps;
}

void process_frame(TimedMap& map, const Frame& frame, StageList& stages) {
  stages.clear();
  try {
    map.process(frame, stages);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("frame {}: {}", frame.index, e.what()));
  }
}

// The first `count` frames through fresh maps of the group's mappers, untimed and then dropped.
// A process's first frames pay for first touches of its heap and its worker threads' arenas,
// which a long run pays once: without this the first group of a bench read 25-45% slower than
// the same group run again (docs/performance.md, "Freed memory kept, and every group warmed up").
void warm_up(const std::vector<Frame>& frames, size_t count, const sim::Scenario& scenario, double voxel,
             const std::vector<std::string>& mappers, Progress& progress, long& done) {
  std::vector<std::unique_ptr<TimedMap>> maps = make_maps(mappers, voxel, scenario);
  StageList stages;
  for (size_t i = 0; i < std::min(count, frames.size()); ++i)
    for (auto& map : maps) {
      process_frame(*map, frames[i], stages);
      progress.update(++done);
    }
}

// One (voxel, threads) group: every mapper integrates frame i before any integrates frame i + 1,
// so a change in the machine's load hits all of them alike and their ratios stay fair.
std::vector<CellResult> time_group(const std::vector<Frame>& frames, const sim::Scenario& scenario,
                                   double voxel, int threads, const std::vector<std::string>& mappers,
                                   size_t warmup, Progress& progress, long& done,
                                   std::optional<ReferenceCheck>& check) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
  // Open3D's own OpenMP loops: their num_threads() clause follows omp_get_max_threads() only
  // when OMP_NUM_THREADS is set (otherwise they take every core), so set both.
  setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), 1);
  omp_set_num_threads(threads);
  const int active = static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  warm_up(frames, warmup, scenario, voxel, mappers, progress, done);
  std::vector<CellResult> cells(mappers.size());
  for (size_t m = 0; m < mappers.size(); ++m) {
    cells[m].voxel = voxel;
    cells[m].threads = active;
    cells[m].mapper = mappers[m];
  }
  std::vector<std::unique_ptr<TimedMap>> maps = make_maps(mappers, voxel, scenario);
  StageList stages;
  for (const Frame& frame : frames)
    for (size_t m = 0; m < mappers.size(); ++m) {
      CellResult& cell = cells[m];
      const double cpu_start = process_cpu_ms();
      process_frame(*maps[m], frame, stages);
      cell.frame_cpu_ms.push_back(process_cpu_ms() - cpu_start);
      for (const auto& [name, ms] : stages) {
        if (!cell.samples.count(name)) cell.stage_order.push_back(name);
        cell.samples[name].push_back(ms);
      }
      cell.peak_map_bytes = std::max(cell.peak_map_bytes, maps[m]->mapper().memory_bytes());
      progress.update(++done);
    }
  std::vector<std::pair<std::string, TimedMap*>> named;
  for (size_t m = 0; m < mappers.size(); ++m) named.emplace_back(mappers[m], maps[m].get());
  check = reference_check(frames, scenario, voxel, active, named);
  return cells;
}

std::string stage_summary(const CellResult& cell) {
  std::string text;
  for (const std::string& name : cell.stage_order)
    if (name != "map" && name != "frame" && name != "raster")
      text += fmt::format("{}{} {:.2f}", text.empty() ? "" : ", ", name, cell.median_of(name));
  return text;
}

// The other two figures, from the same run: per mapper and thread count, a coarser
// voxel's median frame over the finest voxel's ("does a coarser map pay off?"); per mapper and
// voxel, the one-thread median frame over each larger thread count's (the speed-up).
struct Scaling {
  std::string mapper;
  double voxel = 0.0, to_voxel = 0.0;  // voxel -> to_voxel at `threads`
  int threads = 0, to_threads = 0;     // threads -> to_threads at `voxel`
  double value = NAN;
};

std::vector<Scaling> scalings(const std::vector<CellResult>& results) {
  std::vector<Scaling> out;
  for (const CellResult& base : results)
    for (const CellResult& other : results) {
      if (other.mapper != base.mapper || &other == &base) continue;
      const double ratio = other.median_of("frame") / base.median_of("frame");
      const bool finest = std::none_of(results.begin(), results.end(), [&](const CellResult& c) {
        return c.mapper == base.mapper && c.threads == base.threads && c.voxel < base.voxel;
      });
      if (other.threads == base.threads && other.voxel > base.voxel && finest)
        out.push_back({base.mapper, base.voxel, other.voxel, base.threads, base.threads, ratio});
      if (other.voxel == base.voxel && base.threads == 1 && other.threads > 1)
        out.push_back({base.mapper, base.voxel, base.voxel, 1, other.threads, 1.0 / ratio});
    }
  return out;
}

void write_json(const BenchMapOptions& o, const sim::Scenario& scenario, const std::vector<Frame>& frames,
                const InputSummary& input, const std::vector<CellResult>& results, const std::vector<ReferenceCheck>& checks,
                double rss_peak_mb, double rss_frames_mb) {
  const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json out{{"scenario", {{"name", scenario.name}, {"file", o.scenario}}},
           {"code_version", code_version()},
           {"frames", json::array()},
           {"every", o.every},
           {"warmup_frames_per_group", std::min<size_t>(o.warmup, frames.size())},
           {"camera", {{"width", scenario.camera.width}, {"height", scenario.camera.height}}},
           {"input", {{"kind", o.input},
                      {"row_step", o.row_step},
                      {"row_spacing_deg", number(input.row_spacing_deg)},
                      {"median_points", input.median_points}}},
           {"vector_loops", name_of(vector_isa())},
           {"open3d", {{"class", "ScalableTSDFVolume"},
                       {"sdf_trunc_voxels", kPeer.truncation / kPeer.voxel},
                       {"range_m", {kPeer.min_range, kPeer.max_range}},
                       {"omp_wait_policy",
                        omp_wait_policy() ? omp_wait_policy() : "unset (libgomp: spin, then sleep)"},
                       {"timed", "the open3d mapper's integrate: depth image copy with the range "
                                 "limits + Integrate"},
                       {"ratios", "to open3d's median map (fusion) in the same (voxel, threads) cell"}}},
           {"results", json::array()},
           {"open3d_checks", json::array()},
           {"peak_rss_mb", rss_peak_mb},
           {"rss_after_rendering_mb", rss_frames_mb}};
  for (const Frame& f : frames) out["frames"].push_back(f.index);
  for (const CellResult& c : results) {
    json stages = json::object(), samples = json::object();
    for (const std::string& name : c.stage_order) {
      stages[name] = c.median_of(name);
      samples[name] = c.samples.at(name);
    }
    out["results"].push_back({{"voxel", c.voxel},
                              {"threads", c.threads},
                              {"mapper", c.mapper},
                              {"frames", c.samples.at("frame").size()},
                              {"median_ms", stages},
                              {"frame_cpu_median_ms", median(c.frame_cpu_ms)},
                              // Every timed frame's figures, in the order of "frames": for a
                              // user's own statistics, e.g. two builds compared frame by frame.
                              {"samples_ms", samples},
                              {"frame_cpu_ms", c.frame_cpu_ms},
                              {"frame_ratio_to_open3d", number(c.frame_ratio)},
                              {"map_ratio_to_open3d", number(c.map_ratio)},
                              {"peak_map_bytes", c.peak_map_bytes}});
  }
  out["voxel_scaling"] = json::array();
  out["thread_speedup"] = json::array();
  for (const Scaling& sc : scalings(results)) {
    if (sc.voxel != sc.to_voxel)
      out["voxel_scaling"].push_back({{"mapper", sc.mapper}, {"threads", sc.threads}, {"voxel", sc.voxel},
                                      {"to_voxel", sc.to_voxel}, {"frame_ratio", number(sc.value)}});
    else
      out["thread_speedup"].push_back({{"mapper", sc.mapper}, {"voxel", sc.voxel}, {"threads", sc.to_threads},
                                       {"speedup", number(sc.value)}});
  }
  for (const ReferenceCheck& c : checks)
    out["open3d_checks"].push_back({{"voxel", c.voxel},
                                    {"threads", c.threads},
                                    {"open3d_vertices", c.open3d_vertices},
                                    {"tsdf_samples", c.tsdf_samples},
                                    {"median_distance_m", number(c.median_distance)}});
  write_text_file(o.json, out.dump(2) + "\n", is_sonomap_json);
}

void bench_map(const BenchMapOptions& o, const GlobalOptions& global) {
  check_options(o);
  const sim::Scenario scenario = load_scenario(o.scenario);
  try {
    sim::validate(scenario);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.scenario + ": " + e.what());
  }
  const long available = std::min<long>(o.frames, (scenario.frames - 1) / o.every + 1);
  const long cells = static_cast<long>(o.voxels.size() * o.threads.size() * o.mappers.size());
  const long warmup = std::min<long>(o.warmup, available);
  Progress progress("bench map", available * (1 + cells) + warmup * cells, global.quiet);
  long done = 0;
  const std::vector<Frame> frames = render_frames(scenario, o, progress, done);
  const double rss_frames_mb = process_peak_rss_mb();
  const InputSummary input = summarise_input(o, scenario, frames);

  std::vector<CellResult> results;
  std::vector<ReferenceCheck> checks;
  for (double voxel : o.voxels)
    for (int threads : o.threads) {
      std::optional<ReferenceCheck> check;
      for (CellResult& cell : time_group(frames, scenario, voxel, threads, o.mappers,
                                         static_cast<size_t>(warmup), progress, done, check))
        results.push_back(std::move(cell));
      if (check) checks.push_back(*check);
    }
  progress.finish();
  const double rss_peak_mb = process_peak_rss_mb();

  // The reference of a cell: Open3D at the same voxel size and thread count.
  for (CellResult& cell : results)
    for (const CellResult& ref : results)
      if (ref.mapper == kOpen3d && ref.voxel == cell.voxel && ref.threads == cell.threads) {
        cell.frame_ratio = cell.median_of("frame") / ref.median_of("map");
        cell.map_ratio = cell.median_of("map") / ref.median_of("map");
      }

  fmt::print("bench map: '{}', {}x{}, {} frames (every {}-th from 0), {} loops, medians per frame in ms\n",
             scenario.name, scenario.camera.width, scenario.camera.height, frames.size(), o.every,
             name_of(vector_isa()));
  fmt::print("warm-up: the first {} of the frames through fresh maps before each (voxel, threads) group, "
             "untimed (--warmup)\n", warmup);
  fmt::print("input: {}\n", input.text);
  fmt::print("map = the mapper's integrate (open3d: depth copy + Integrate, truncation {:g} voxels); "
             "raster = circle + cylinder\nfrom the map's surface samples (as `run`; open3d: mesh "
             "extraction included); frame = map + raster;\ncpu = process CPU time of the frame (all "
             "threads); frame/o3d, map/o3d = ratios of the medians to open3d's map\n(its fusion) in "
             "the same (voxel, threads) cell.\n",
             kPeer.truncation / kPeer.voxel);
  const auto ms = [](double v) { return std::isfinite(v) ? fmt::format("{:.2f}", v) : std::string("-"); };
  fmt::print("{:>6} {:>3} {:<10} {:>6} | {:>9} {:>9} {:>9} {:>9} | {:>9} {:>9} | {:>9} | {}\n", "voxel",
             "thr", "mapper", "frames", "frame", "cpu", "map", "raster", "frame/o3d", "map/o3d",
             "peak MB", "stages");
  for (const CellResult& c : results)
    fmt::print("{:>6.2f} {:>3} {:<10} {:>6} | {:>9} {:>9} {:>9} {:>9} | {:>9} {:>9} | {:>9.1f} | {}\n",
               c.voxel, c.threads, c.mapper, c.samples.at("frame").size(), ms(c.median_of("frame")),
               ms(median(c.frame_cpu_ms)), ms(c.median_of("map")),
               ms(c.samples.count("raster") ? c.median_of("raster") : NAN), ms(c.frame_ratio),
               ms(c.map_ratio), c.peak_map_bytes / 1048576.0, stage_summary(c));
  for (const ReferenceCheck& c : checks)
    fmt::print("open3d check, voxel {:.2f}, {} threads: {} mesh vertices, median distance to the "
               "TSDF's {} surface samples {:.4f} m ({:.2f} voxels): {}\n",
               c.voxel, c.threads, c.open3d_vertices, c.tsdf_samples, c.median_distance,
               c.median_distance / c.voxel, c.passed() ? "ok" : "FAILED");
  for (const Scaling& sc : scalings(results)) {
    if (sc.voxel != sc.to_voxel)
      fmt::print("{}, {} thread(s): frame at {:g} m / frame at {:g} m = {:.2f}\n", sc.mapper, sc.threads,
                 sc.to_voxel, sc.voxel, sc.value);
    else
      fmt::print("{}, {:g} m: {} threads are {:.2f}x as fast as 1 (median frame)\n", sc.mapper, sc.voxel,
                 sc.to_threads, sc.value);
  }
  fmt::print("peak RSS: {:.1f} MB for the whole run ({:.1f} MB after rendering the frames)\n",
             rss_peak_mb, rss_frames_mb);
  if (!omp_wait_policy() && std::any_of(o.threads.begin(), o.threads.end(), [](int t) { return t > 1; }))
    fmt::print("note: OMP_WAIT_POLICY is unset, so Open3D's OpenMP threads spin before they "
               "sleep: on a busy machine\nits multi-thread times are mostly spinning "
               "(OMP_WAIT_POLICY=PASSIVE measures a shared machine).\n");

  const bool reference_ok =
      std::all_of(checks.begin(), checks.end(), [](const ReferenceCheck& c) { return c.passed(); });
  if (!o.json.empty()) write_json(o, scenario, frames, input, results, checks, rss_peak_mb, rss_frames_mb);
  if (!reference_ok)
    throw std::runtime_error("bench map: the Open3D reference failed its check (its surface is not "
                             "within a voxel of our TSDF's): the ratios are not valid");
}

}  // namespace

void add_bench_map(CLI::App& bench, const GlobalOptions& global) {
  auto options = std::make_shared<BenchMapOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "map", "Mapping speed: median ms per frame of each stage (and the rasters) per voxel size,\n"
             "thread count and mapper, against Open3D's ScalableTSDFVolume on the same frames");
  cmd->add_option("scenario", options->scenario, "Scenario YAML")->capture_default_str();
  cmd->add_option("--frames", options->frames, "Frames to integrate and time")->capture_default_str();
  cmd->add_option("--every", options->every, "Take every K-th frame of the scenario (from frame 0)")
      ->capture_default_str();
  cmd->add_option("--warmup", options->warmup,
                  fmt::format("Frames integrated untimed by fresh maps before each (voxel, threads) "
                              "group, so that none pays the process's first touches of memory "
                              "(0-{})", kMaxWarmup))
      ->capture_default_str();
  cmd->add_option("--voxels", options->voxels, "Voxel sizes in metres")
      ->delimiter(',')->capture_default_str();
  cmd->add_option("--threads-list", options->threads, "Thread counts (TBB and Open3D's OpenMP)")
      ->delimiter(',')->capture_default_str();
  cmd->add_option("--mappers", options->mappers, "Mappers: vdb_gpdf, tsdf, depth_only, open3d")
      ->delimiter(',')->capture_default_str();
  cmd->add_option("--input", options->input,
                  "image: depth images and their points; cloud: the points only, as a recording's "
                  "unorganised cloud (open3d fuses images only)")
      ->check(CLI::IsMember({"image", "cloud"}))->capture_default_str();
  cmd->add_option("--row-step", options->row_step,
                  "With --input cloud: keep every N-th image row's points only, lines across each "
                  "surface as a spinning lidar's rings (18 rows of a 525 px focal length: 2 degrees)")
      ->capture_default_str();
  cmd->add_option("--json", options->json, "Write the results as JSON (atomically)");
  const auto loops = add_vector_loops_option(*cmd);
  cmd->callback([options, loops, &global] { with_vector_loops(*loops, [&] { bench_map(*options, global); }); });
}

}  // namespace sonomap::harness
