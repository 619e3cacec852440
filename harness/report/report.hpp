// SPDX-License-Identifier: GPL-3.0-or-later
// Roll-up of many result directories: rollup.csv (one row per run), plots (gnuplot PNG) and
// report.md with tables. Works on whatever finished runs exist under <dir>/runs.
#pragma once

#include "harness/app/cli.hpp"

#include <filesystem>

namespace sonomap::harness {

// Returns the number of runs rolled up. Throws InputError when <dir>/runs has no finished run.
int build_report(const std::filesystem::path& dir, bool quiet);

void add_report_command(CLI::App& app, const GlobalOptions& global);

}  // namespace sonomap::harness
