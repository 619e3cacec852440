// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/rollup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace sonomap::harness {

namespace {

std::string number_text(double v, const char* format) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : "";
}

// coverage, rmse, rmse_off_edges and ghosts of a raster's final frame and its means (NaN where
// the run has no such raster or frame).
using FourMetrics = std::array<double, 4>;
std::pair<FourMetrics, FourMetrics> final_and_mean(const RasterSummary* r) {
  FourMetrics final_frame{NAN, NAN, NAN, NAN}, mean{NAN, NAN, NAN, NAN};
  if (r && r->final_frame) {
    const eval::RasterMetrics& m = *r->final_frame;
    final_frame = {m.coverage, m.rmse, m.rmse_off_edges, static_cast<double>(m.ghosts)};
  }
  if (r) mean = {r->mean.coverage, r->mean.rmse, r->mean.rmse_off_edges, r->mean.ghosts};
  return {final_frame, mean};
}

// The moved objects' ghosts as three numbers: the worst clearing (frames; undefined when an
// object never cleared or none was seen empty), the ghost bins left at the end and the objects
// that never cleared (all undefined without moving objects).
std::array<double, 3> moved_ghost_figures(const std::vector<eval::MovedObjectClearing>& objects) {
  if (objects.empty()) return {NAN, NAN, NAN};
  double worst = NAN, left = 0, uncleared = 0;
  for (const eval::MovedObjectClearing& m : objects) {
    left += m.ghost_bins_at_end;
    if (m.seen_empty_frame && !m.cleared()) ++uncleared;
    if (m.clearing_frames) worst = std::isfinite(worst) ? std::max<double>(worst, *m.clearing_frames) : *m.clearing_frames;
  }
  return {uncleared > 0 ? NAN : worst, left, uncleared};
}

}  // namespace

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

RollupTable RollupTable::parse(const std::string& csv_text) {
  RollupTable table;
  std::istringstream in(csv_text);
  std::string line;
  if (std::getline(in, line)) table.header = split_csv_line(line);
  while (std::getline(in, line))
    if (!line.empty()) table.rows.push_back(split_csv_line(line));
  return table;
}

int RollupTable::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : static_cast<int>(it - header.begin());
}

const std::string& RollupTable::cell(const std::vector<std::string>& row, int column) const {
  static const std::string empty;
  return column >= 0 && static_cast<std::size_t>(column) < row.size() ? row[column] : empty;
}

double RollupTable::number(const std::vector<std::string>& row, int column) const {
  const std::string& text = cell(row, column);
  if (text.empty()) return std::numeric_limits<double>::quiet_NaN();
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return *end == '\0' ? v : std::numeric_limits<double>::quiet_NaN();
}

std::vector<std::string> RollupTable::metrics() const {
  const int frames = column("frames");
  return frames < 0 ? std::vector<std::string>{} : std::vector<std::string>(header.begin() + frames + 1, header.end());
}

std::vector<std::pair<std::string, std::string>> summary_metrics(const RunSummary& summary) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::pair<const char*, const RasterSummary*> rasters[] = {
      {"circle", &summary.circle}, {"cylinder", &summary.cylinder},
      {"edf_circle", summary.edf_circle ? &*summary.edf_circle : nullptr}};
  const char* names[] = {"coverage", "rmse", "rmse_off_edges", "ghosts"};
  for (const auto& [raster, r] : rasters) {
    const auto [final_frame, mean] = final_and_mean(r);
    for (const auto& [which, values] : {std::pair{"final", final_frame}, std::pair{"mean", mean}})
      for (std::size_t i = 0; i < values.size(); ++i)
        out.emplace_back(fmt::format("{}_{}_{}", raster, which, names[i]), number_text(values[i], "{:.6g}"));
  }
  const std::optional<SlipStats> slip_final = summary.edf ? summary.edf->final_slip : std::nullopt;
  const double slip[2][2] = {{slip_final ? slip_final->median_deg : NAN, slip_final ? slip_final->p90_deg : NAN},
                             {summary.edf ? summary.edf->mean_median_deg : NAN,
                              summary.edf ? summary.edf->mean_p90_deg : NAN}};
  for (int w = 0; w < 2; ++w)
    for (int n = 0; n < 2; ++n)
      out.emplace_back(fmt::format("edf_slip_{}_{}", w ? "mean" : "final", n ? "p90_deg" : "median_deg"),
                       number_text(slip[w][n], "{:.2f}"));
  const auto moved = moved_ghost_figures(summary.moved_objects);
  const char* moved_names[] = {"moved_ghosts_clearing_frames", "moved_ghosts_at_end", "moved_ghosts_uncleared"};
  for (std::size_t i = 0; i < moved.size(); ++i) out.emplace_back(moved_names[i], number_text(moved[i], "{:.0f}"));
  return out;
}

}  // namespace sonomap::harness
