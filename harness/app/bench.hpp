// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap bench ...`: speed measurements reported as medians (never asserted in tests).
// Each benchmark registers itself as a subcommand of `bench`.
#pragma once

#include "harness/app/cli.hpp"

#include <algorithm>
#include <ctime>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace sonomap::harness {

// `sonomap bench render [SCENARIO] [--frames N]`: ms per depth frame and Mrays/s, 1 and 2 threads.
void add_bench_render(CLI::App& bench, const GlobalOptions& global);
// `sonomap bench sonify`: median ms per 36-sector sweep, BRIR spectra cached and uncached.
void add_bench_sonify(CLI::App& bench, const GlobalOptions& global);
// `sonomap bench map [SCENARIO]`: median ms per frame of each mapping stage and the rasters, per
// voxel size, thread count and mapper, as ratios to Open3D's ScalableTSDFVolume on the same frames.
void add_bench_map(CLI::App& bench, const GlobalOptions& global);

// `--vector-loops best|baseline|avx2|avx512` on a benchmark: which copy of the vectorised loops
// it runs (core/vector_isa.hpp; every copy computes the same bits). A machine with AVX-512 can
// then time the loops an AVX2 or a baseline x86-64 machine runs. Returns where the choice is kept.
std::shared_ptr<std::string> add_vector_loops_option(CLI::App& cmd);
// Runs `bench` on the loops chosen; one this CPU lacks is an InputError (exit 2).
void with_vector_loops(const std::string& choice, const std::function<void()>& bench);

// The median of a non-empty sample (mean of the two middle values for an even count).
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// CPU time of the whole process (all threads), ms. On a busy machine wall time includes waiting
// for a core; the one-thread CPU time is the better estimate of an idle core's wall time.
inline double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

}  // namespace sonomap::harness
