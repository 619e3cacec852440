// SPDX-License-Identifier: GPL-3.0-or-later
// The report's statistics over seeds (stats.hpp) as files: rollup_stats.csv (per scenario and
// variant, every metric: n, mean, sd, 95% interval), pairs.csv (per scenario, and over all
// scenarios when there are several: every pair of variants, every metric, the paired
// difference candidate - baseline over the same seeds with its interval and verdict), plots
// with error bars, and the report.md section that shows the headline metrics.
#pragma once

#include "harness/report/rollup.hpp"

#include <filesystem>
#include <string>

namespace sonomap::harness {

// Writes DIR/rollup_stats.csv, DIR/pairs.csv and DIR/plots/<scenario>_stats_<metric>.png;
// returns the markdown section.
std::string stats_section(const std::filesystem::path& dir, const RollupTable& rollup);

}  // namespace sonomap::harness
