// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/run_settings.hpp"

#include "harness/support/errors.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

namespace sonomap::harness {
namespace {

bool is_run_key(const std::string& key) {
  for (const char* prefix : {"mapper.", "raster.", "metrics.", "edf."})
    if (key.rfind(prefix, 0) == 0) return true;
  return false;
}

double parse_number(const Setting& s) {
  try {
    size_t used = 0;
    const double v = std::stod(s.value, &used);
    if (used == s.value.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw InputError(s.source + ": key '" + s.key + "': expected a number, got '" + s.value + "'");
}

void apply_run_setting(RunSettings& settings, const Setting& s) {
  const std::string& k = s.key;
  if (k.rfind("mapper.", 0) == 0) {
    settings.mapper.push_back({k.substr(7), s.value, s.source});
    return;
  }
  std::map<std::string, double*> numbers = {
      {"raster.band_min", &settings.raster.band_min},
      {"raster.band_max", &settings.raster.band_max},
      {"raster.row_height", &settings.raster.row_height},
      {"raster.max_range", &settings.raster.max_range},
      {"metrics.ghost_tolerance", &settings.metrics.ghost_tolerance},
      {"metrics.edge_jump", &settings.metrics.edge_jump},
      {"edf.sample_radius", &settings.edf.sample_radius},
      {"edf.hit_tolerance", &settings.edf.hit_tolerance},
      {"edf.max_range", &settings.edf.max_range},
  };
  if (auto it = numbers.find(k); it != numbers.end()) {
    *it->second = parse_number(s);
    if (k == "metrics.ghost_tolerance") settings.ghost_tolerance_set = true;
    if (k == "edf.max_range") settings.edf_max_range_set = true;
    if (k.rfind("edf.", 0) == 0 && !(*it->second > 0.0))
      throw InputError(s.source + ": key '" + k + "': expected a number > 0, got '" + s.value + "'");
    return;
  }
  if (k == "edf.max_steps" || k == "edf.every") {
    const double v = parse_number(s);
    if (v != std::floor(v) || v < 1 || v > 1e6)
      throw InputError(s.source + ": key '" + k + "': expected a whole number in [1, 1000000]");
    (k == "edf.every" ? settings.edf_every : settings.edf.max_steps) = static_cast<int>(v);
    return;
  }
  if (k == "edf.trace_rows") {
    const double v = parse_number(s);
    if (v != std::floor(v) || v < 0 || v > 100)
      throw InputError(s.source + ": key '" + k + "': expected a whole number in [0, 100]");
    settings.edf_trace_rows = static_cast<int>(v);
    return;
  }
  if (k == "edf.enabled") {
    if (s.value != "true" && s.value != "false")
      throw InputError(s.source + ": key '" + k + "': expected true or false, got '" + s.value + "'");
    settings.edf_enabled = s.value == "true";
    return;
  }
  if (k == "raster.azimuth_bins") {
    const double v = parse_number(s);
    if (v != std::floor(v) || v < 1 || v > 36000)
      throw InputError(s.source + ": key '" + k + "': expected a whole number in [1, 36000]");
    settings.raster.azimuth_bins = static_cast<int>(v);
    return;
  }
  throw InputError(s.source + ": unknown key '" + k +
                   "' (run keys: mapper.*, raster.band_min, raster.band_max, raster.row_height, "
                   "raster.max_range, raster.azimuth_bins, metrics.ghost_tolerance, "
                   "metrics.edge_jump, edf.enabled, edf.every, edf.sample_radius, "
                   "edf.hit_tolerance, edf.max_steps, edf.max_range, edf.trace_rows)");
}

}  // namespace

// Splits "key=value" overrides into scenario overrides and run settings.
void split_overrides(const std::vector<std::string>& overrides, std::vector<std::string>& scenario,
                     RunSettings& settings) {
  for (const std::string& o : overrides) {
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--set " + o + ": expected key=value");
    const std::string key = o.substr(0, eq);
    if (is_run_key(key))
      apply_run_setting(settings, {key, o.substr(eq + 1), "--set " + o});
    else
      scenario.push_back(o);
  }
  try {
    settings.raster.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--set raster.*: ") + e.what());
  }
  if (!settings.edf_max_range_set) settings.edf.max_range = settings.raster.max_range;
  // The EDF circle's rays at the centres of equal slices of the band the circle covers.
  const double slice = (settings.raster.band_max - settings.raster.band_min) / std::max(1, settings.edf_trace_rows);
  settings.edf.trace_heights.clear();
  for (int j = 0; j < settings.edf_trace_rows; ++j)
    settings.edf.trace_heights.push_back(settings.raster.band_min + (j + 0.5) * slice);
  try {
    settings.edf.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--set edf.*: ") + e.what());
  }
}


}  // namespace sonomap::harness
