// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap bench`: the benchmark group, and `bench render`, the depth sensor's speed.
#include "harness/app/bench.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/progress.hpp"
#include "sim/depth_camera.hpp"
#include "sim/noise.hpp"
#include "sim/primitives.hpp"
#include "sim/simulation.hpp"
#include "core/vector_isa.hpp"
#include "sim/world.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <map>
#include <utility>
#include <memory>
#include <stdexcept>

namespace sonomap::harness {

namespace {

struct BenchRenderOptions {
  std::string scenario;  // empty: the built-in room
  int frames = 60;
};

sim::StaticObject box(const std::string& name, const Eigen::Vector3d& size, const Eigen::Vector3d& position,
                      double yaw = 0.0) {
  sim::StaticObject o;
  o.name = name;
  o.shape.kind = sim::PrimitiveSpec::Kind::Box;
  o.shape.size = size;
  o.pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  o.pose.translation() = position;
  return o;
}

sim::StaticObject cylinder(const std::string& name, double radius, double height, const Eigen::Vector3d& position) {
  sim::StaticObject o;
  o.name = name;
  o.shape.kind = sim::PrimitiveSpec::Kind::Cylinder;
  o.shape.radius = radius;
  o.shape.height = height;
  o.pose.translation() = position;
  return o;
}

// Like scenes/room.yaml, from primitives only: the Cow and Lady sized room with a cow-sized box,
// a person-sized cylinder, a table, a shelf, a column and a ball; the listener at 1.5 m turns a
// full circle in 12 s with the camera pitched 15 degrees down; Kinect noise on.
sim::Scenario builtin_room() {
  sim::Scenario s;
  s.name = "room (built-in)";
  sim::StaticObject room = box("room", {3.5, 6.0, 2.8}, {-1.25, 0.0, 0.0});
  room.shape.kind = sim::PrimitiveSpec::Kind::Room;
  s.statics.push_back(room);
  s.statics.push_back(box("cow", {2.0, 0.7, 1.5}, {-1.8, 1.9, 0.0}));
  s.statics.push_back(cylinder("person", 0.25, 1.75, {-0.15, -2.0, 0.0}));
  s.statics.push_back(box("table_top", {1.2, 0.8, 0.04}, {-2.3, -1.4, 0.71}));
  for (double x : {-2.85, -1.75})
    for (double y : {-1.75, -1.05}) s.statics.push_back(box("table_leg", {0.05, 0.05, 0.71}, {x, y, 0.0}));
  s.statics.push_back(box("shelf", {1.2, 0.35, 1.8}, {-1.0, -2.8, 0.0}));
  s.statics.push_back(cylinder("column", 0.15, 2.8, {-0.25, 1.0, 0.0}));
  s.statics.push_back(box("bin", {0.4, 0.4, 0.4}, {0.1, -0.6, 0.0}, 0.35));
  sim::StaticObject ball;
  ball.name = "ball";
  ball.shape.kind = sim::PrimitiveSpec::Kind::Sphere;
  ball.shape.radius = 0.3;
  ball.pose.translation() = Eigen::Vector3d(-2.5, 0.5, 0.3);
  s.statics.push_back(ball);

  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = Eigen::AngleAxisd(15.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  s.camera.body_T_camera = mount * sim::CameraSpec::default_body_T_camera();
  s.noise.model = sim::NoiseSpec::Model::Kinect;
  for (int k = 0; k <= 4; ++k) {
    const double yaw = k * M_PI / 2;
    s.body.keyframes.push_back(sim::Keyframe{3.0 * k, Eigen::Vector3d(-1.2, 0.0, 1.5),
                                             Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))});
  }
  s.frames = 360;
  return s;
}

// Wall time and CPU time (all threads) of one call, in ms. On a busy machine the CPU time of
// the one-thread run is the better estimate of the wall time on an idle core.
template <typename F>
std::pair<double, double> milliseconds(const F& work) {
  const double cpu_start = process_cpu_ms();
  const auto start = std::chrono::steady_clock::now();
  work();
  const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return {wall, process_cpu_ms() - cpu_start};
}

struct Timing {
  int threads = 0;
  double rays_ms = 0.0;    // median ray casting (World::cast) per frame
  double rays_cpu_ms = 0.0;
  double noise_ms = 0.0;   // median sim::apply_noise per frame (the noise stage alone)
  double noise_cpu_ms = 0.0;
  double render_ms = 0.0;  // median Simulation::render per frame (rays, noise, points, poses)
  double render_cpu_ms = 0.0;
};

Timing time_frames(const sim::Scenario& scenario, const std::vector<int>& frames, int threads, Progress& progress,
                   long& done) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  Timing timing;
  timing.threads = static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

  sim::Simulation simulation(scenario);
  sim::World world(simulation.scenario());
  sim::PinholeRays rays = sim::PinholeRays::of(scenario.camera, Eigen::Isometry3d::Identity());
  const sim::DepthCamera camera(simulation.scenario().camera);

  simulation.render(frames.front());  // warm-up: first-touch allocations and TBB workers
  std::vector<double> rays_ms, rays_cpu_ms, noise_ms, noise_cpu_ms, render_ms, render_cpu_ms;
  sim::RayHits hits;  // buffers reused across frames, as Simulation::render does
  sim::DepthImage truth, noisy;
  for (int frame : frames) {
    const double t = simulation.time_of(frame);
    world.set_time(t);
    rays.world_T_camera = simulation.true_camera_pose(t);
    const auto [cast_wall, cast_cpu] = milliseconds([&] { world.cast(rays, hits); });
    camera.trace(world, rays.world_T_camera, truth);
    const sim::NoiseKey key{scenario.seed, 0, static_cast<std::uint64_t>(frame)};
    const auto [noise_wall, noise_cpu] =
        milliseconds([&] { sim::apply_noise(truth, scenario.noise, scenario.camera.fx, key, noisy); });
    const auto [render_wall, render_cpu] = milliseconds([&] { simulation.render(frame); });
    rays_ms.push_back(cast_wall);
    rays_cpu_ms.push_back(cast_cpu);
    noise_ms.push_back(noise_wall);
    noise_cpu_ms.push_back(noise_cpu);
    render_ms.push_back(render_wall);
    render_cpu_ms.push_back(render_cpu);
    progress.update(++done);
  }
  timing.rays_ms = median(rays_ms);
  timing.rays_cpu_ms = median(rays_cpu_ms);
  timing.noise_ms = median(noise_ms);
  timing.noise_cpu_ms = median(noise_cpu_ms);
  timing.render_ms = median(render_ms);
  timing.render_cpu_ms = median(render_cpu_ms);
  return timing;
}

void bench_render(const BenchRenderOptions& options, const GlobalOptions& global) {
  sim::Scenario scenario;
  if (options.scenario.empty()) {
    scenario = builtin_room();
  } else {
    scenario = load_scenario(options.scenario);
  }
  try {
    sim::validate(scenario);
  } catch (const std::invalid_argument& e) {
    throw InputError(options.scenario.empty() ? "built-in room" : options.scenario, 0, "", e.what());
  }
  const int count = std::max(1, std::min(options.frames, scenario.frames));
  std::vector<int> frames;
  for (int i = 0; i < count; ++i) frames.push_back(static_cast<int>(static_cast<long>(i) * scenario.frames / count));

  std::size_t triangles = 0;
  for (const auto& o : scenario.statics) triangles += sim::mesh_of(o.shape, o.mesh).triangles.size();
  for (const auto& o : scenario.movers) triangles += sim::mesh_of(o.shape, o.mesh).triangles.size();

  Progress progress("bench render", 2L * count, global.quiet);
  long done = 0;
  std::vector<Timing> timings;
  for (int threads : {1, 2}) timings.push_back(time_frames(scenario, frames, threads, progress, done));
  progress.finish();

  const double rays = static_cast<double>(scenario.camera.width) * scenario.camera.height;
  std::printf("bench render: '%s', %dx%d, %zu triangles, %d frames, noise %s, %s loops, Embree packets "
              "of %d rays (medians)\n",
              scenario.name.c_str(), scenario.camera.width, scenario.camera.height, triangles, count,
              scenario.noise.model == sim::NoiseSpec::Model::None ? "none" : "kinect",
              name_of(vector_isa()), sim::native_packet_rays());
  std::printf("rays: Embree casting only; noise: the noise model alone (sim::apply_noise on the exact\n"
              "image); render: Simulation::render (rays, noise, points, poses), Mrays/s = pixels / render.\n"
              "wall = elapsed time; cpu = CPU time of all threads (the 1-thread cpu figure is the\n"
              "best estimate of an idle core when the machine is busy).\n");
  std::printf("%7s | %12s %12s %12s | %13s %12s | %14s %13s %12s %12s\n", "threads", "rays wall ms",
              "Mrays/s wall", "rays cpu ms", "noise wall ms", "noise cpu ms", "render wall ms",
              "render cpu ms", "Mrays/s wall", "Mrays/s cpu");
  for (const Timing& t : timings)
    std::printf("%7d | %12.2f %12.1f %12.2f | %13.2f %12.2f | %14.2f %13.2f %12.1f %12.1f\n", t.threads,
                t.rays_ms, rays / (t.rays_ms * 1e3), t.rays_cpu_ms, t.noise_ms, t.noise_cpu_ms, t.render_ms,
                t.render_cpu_ms, rays / (t.render_ms * 1e3), rays / (t.render_cpu_ms * 1e3));
}

// The loops `--vector-loops` names; "best" is what runs by default, the widest copy this CPU has.
std::map<std::string, VectorIsa> named_loops() {
  return {{"best", vector_isa()},
          {"baseline", VectorIsa::Baseline},
          {"avx2", VectorIsa::Avx2},
          {"avx512", VectorIsa::Avx512}};
}

}  // namespace

std::shared_ptr<std::string> add_vector_loops_option(CLI::App& cmd) {
  auto choice = std::make_shared<std::string>("best");
  std::vector<std::string> names;
  for (const auto& [name, isa] : named_loops()) names.push_back(name);
  cmd.add_option("--vector-loops", *choice,
                 "The vectorised loops to run: best (the widest this CPU has), baseline, avx2 or avx512 "
                 "(the same results; the speed of a lesser CPU)")
      ->check(CLI::IsMember(names))
      ->capture_default_str();
  return choice;
}

void with_vector_loops(const std::string& choice, const std::function<void()>& bench) {
  const VectorIsa isa = named_loops().at(choice);  // the option's check took only these names
  if (!supported(isa)) throw InputError("--vector-loops " + choice + ": this CPU lacks " + name_of(isa));
  const ScopedVectorIsa loops(isa);
  bench();
}

void add_bench_render(CLI::App& bench, const GlobalOptions& global) {
  auto options = std::make_shared<BenchRenderOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "render", "Depth rendering speed: median ms per frame and Mrays/s at 1 and 2 threads");
  cmd->add_option("scenario", options->scenario, "Scenario YAML (default: a built-in room)");
  cmd->add_option("--frames", options->frames, "Frames to time, spread over the scenario (default 60)")
      ->check(CLI::PositiveNumber);
  const auto loops = add_vector_loops_option(*cmd);
  cmd->callback([options, loops, &global] { with_vector_loops(*loops, [&] { bench_render(*options, global); }); });
}

void add_bench_command(CLI::App& app, const GlobalOptions& global) {
  CLI::App* bench = app.add_subcommand("bench", "Speed measurements (medians)");
  bench->require_subcommand(1);
  add_bench_render(*bench, global);
  add_bench_sonify(*bench, global);
  add_bench_map(*bench, global);
}

}  // namespace sonomap::harness
