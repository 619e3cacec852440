// SPDX-License-Identifier: GPL-3.0-or-later
// Roll-up of many result directories: rollup.csv (one row per run), statistics over seeds
// (rollup_stats.csv, pairs.csv; stats.hpp), plots (gnuplot PNG) and report.md with tables,
// gates and claims. Works on whatever finished runs exist under <dir>/runs.
#pragma once

#include "harness/app/cli.hpp"

#include <filesystem>

namespace sonomap::harness {

struct ReportOutcome {
  int runs = 0;          // runs rolled up
  int failed_gates = 0;  // gates (DIR/gates.json) that fail or cannot be measured
};

// Writes rollup.csv, rollup_stats.csv, pairs.csv, plots/ and report.md in `dir` (and JUnit XML
// to `junit` unless empty). Throws InputError when <dir>/runs has no finished run.
ReportOutcome build_report(const std::filesystem::path& dir, bool quiet,
                           const std::filesystem::path& junit = {});

void add_report_command(CLI::App& app, const GlobalOptions& global);

}  // namespace sonomap::harness
