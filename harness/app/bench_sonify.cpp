// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap bench sonify`: median time to render one 36-sector sweep, with the BRIR spectra
// cached (the steady state of a run) and uncached (the first sweep), at 1 and 2 threads.
#include "harness/app/bench.hpp"
#include "harness/app/sonify.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>

namespace sonomap::harness {

namespace {

struct BenchSonifyOptions {
  SonifySetup setup;
  int repetitions = 30;
};

// The listener in the middle of a 5 x 4 m room: every bin sees a wall 2..3.2 m away, so all
// 36 sectors tap, over several BRIR distances.
Circle room_circle() {
  Circle c(360);
  const double pi = 3.14159265358979323846;
  for (int k = 0; k < 360; ++k) {
    const double a = (k + 0.5) * pi / 180.0;
    const double tx = 2.5 / std::max(1e-9, std::abs(std::cos(a)));
    const double ty = 2.0 / std::max(1e-9, std::abs(std::sin(a)));
    c.bins[k].range = static_cast<float>(std::min(tx, ty));
  }
  return c;
}

void bench_sonify(const BenchSonifyOptions& o, const GlobalOptions& global) {
  check_sweep_options(o.setup);
  const auto t0 = std::chrono::steady_clock::now();
  auto brirs = load_brirs(o.setup, global.quiet);
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  audio::SweepRenderer renderer(brirs, o.setup.sweep);
  const Circle circle = room_circle();
  const size_t events = renderer.schedule(circle).size();
  std::printf("bench sonify: %zu sounds per sweep, BRIRs of %zu samples at %.0f Hz (%s in %.1f s), "
              "FFT size %zu, %d repetitions\n",
              events, brirs->ir_length(), brirs->sample_rate(),
              o.setup.brir_dir.empty() ? "synthesised" : "loaded", load_s,
              renderer.fft_size(), o.repetitions);
  std::printf("%7s | %16s %16s | %18s %18s | %14s\n", "threads", "cached wall ms",
              "cached cpu ms", "uncached wall ms", "uncached cpu ms", "cpu ms/tap+ear");
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    std::vector<double> cached, uncached, cached_cpu, uncached_cpu;
    for (int i = 0; i < o.repetitions; ++i) {
      renderer.clear_cache();
      const auto a = std::chrono::steady_clock::now();
      const double ca = process_cpu_ms();
      const audio::SweepAudio cold = renderer.render(circle);
      const auto b = std::chrono::steady_clock::now();
      const double cb = process_cpu_ms();
      const audio::SweepAudio warm = renderer.render(circle);
      const auto c = std::chrono::steady_clock::now();
      const double cc = process_cpu_ms();
      uncached.push_back(std::chrono::duration<double, std::milli>(b - a).count());
      cached.push_back(std::chrono::duration<double, std::milli>(c - b).count());
      uncached_cpu.push_back(cb - ca);
      cached_cpu.push_back(cc - cb);
      if (warm.left != cold.left) throw std::runtime_error("bench: cached and uncached differ");
    }
    std::printf("%7d | %16.2f %16.2f | %18.2f %18.2f | %14.3f\n", threads, median(cached),
                median(cached_cpu), median(uncached), median(uncached_cpu),
                median(cached_cpu) / (2.0 * std::max<size_t>(1, events)));
  }
}

}  // namespace

void add_bench_sonify(CLI::App& bench, const GlobalOptions& global) {
  auto options = std::make_shared<BenchSonifyOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "sonify", "Sweep rendering speed: median ms per 36-sector sweep, BRIR spectra cached and "
                "uncached, at 1 and 2 threads (default: BRIRs synthesised for a 5x4x3 m room)");
  add_sonify_options(*cmd, options->setup);
  cmd->add_option("--repetitions", options->repetitions, "Sweeps timed per setting")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cmd->callback([options, &global] { bench_sonify(*options, global); });
}

}  // namespace sonomap::harness
