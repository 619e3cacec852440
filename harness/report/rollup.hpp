// SPDX-License-Identifier: GPL-3.0-or-later
// The roll-up's table (rollup.csv): one row per run, the columns run, scenario, variant,
// mapper, voxel, seed, frames and then one column per metric. Claims, gates, statistics and
// `diff` read their numbers through it, so they all name metrics the same way.
#pragma once

#include "harness/formats/run_summary.hpp"

#include <string>
#include <utility>
#include <vector>

namespace sonomap::harness {

// The cells of one CSV line (no quoting: sonomap's CSVs hold none); a trailing comma is an
// empty last cell.
std::vector<std::string> split_csv_line(const std::string& line);

struct RollupTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  static RollupTable parse(const std::string& csv_text);
  int column(const std::string& name) const;  // -1 when there is no such column
  // The cell as a number; NaN when empty, missing or the column is -1.
  double number(const std::vector<std::string>& row, int column) const;
  const std::string& cell(const std::vector<std::string>& row, int column) const;
  // The metric columns (everything after "frames").
  std::vector<std::string> metrics() const;
};

// A result directory's metrics under their rollup.csv names (circle_final_coverage, ...,
// edf_slip_mean_p90_deg, moved_ghosts_clearing_frames, moved_ghosts_at_end,
// moved_ghosts_uncleared), from its summary; "" where a metric is undefined or absent.
std::vector<std::pair<std::string, std::string>> summary_metrics(const RunSummary& summary);

}  // namespace sonomap::harness
