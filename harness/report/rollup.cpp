// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/report/rollup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <sstream>

using nlohmann::json;

namespace sonomap::harness {

namespace {

std::string number_text(const json& v, const char* format) {
  return v.is_number() ? fmt::format(fmt::runtime(format), v.get<double>()) : "";
}

// summary["metrics"][raster][which][name], or the EDF slip summary["edf"]["slip"][which][name].
const json& lookup(const json& summary, std::initializer_list<const char*> path) {
  static const json null;
  const json* at = &summary;
  for (const char* key : path) {
    if (!at->is_object() || !at->contains(key)) return null;
    at = &(*at)[key];
  }
  return *at;
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

std::vector<std::pair<std::string, std::string>> summary_metrics(const json& summary) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const char* raster : {"circle", "cylinder", "edf_circle"})
    for (const char* which : {"final", "mean"})
      for (const char* name : {"coverage", "rmse", "rmse_off_edges", "ghosts"})
        out.emplace_back(fmt::format("{}_{}_{}", raster, which, name),
                         number_text(lookup(summary, {"metrics", raster, which, name}), "{:.6g}"));
  for (const char* which : {"final", "mean"})
    for (const char* name : {"median_deg", "p90_deg"})
      out.emplace_back(fmt::format("edf_slip_{}_{}", which, name),
                       number_text(lookup(summary, {"edf", "slip", which, name}), "{:.2f}"));
  return out;
}

}  // namespace sonomap::harness
