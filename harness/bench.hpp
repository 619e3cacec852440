// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap bench ...`: speed measurements reported as medians (never asserted in tests).
// Each benchmark registers itself as a subcommand of `bench`.
#pragma once

#include "harness/cli.hpp"

namespace sonomap::harness {

// `sonomap bench render [SCENARIO] [--frames N]`: ms per depth frame and Mrays/s, 1 and 2 threads.
void add_bench_render(CLI::App& bench, const GlobalOptions& global);
// `sonomap bench sonify`: median ms per 36-sector sweep, BRIR spectra cached and uncached.
void add_bench_sonify(CLI::App& bench, const GlobalOptions& global);

}  // namespace sonomap::harness
