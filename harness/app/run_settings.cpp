// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/run_settings.hpp"

#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "harness/app/config_fields.hpp"
#include "harness/support/errors.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <stdexcept>

namespace sonomap::harness {
namespace {

bool is_run_key(const std::string& key) {
  for (const char* prefix : {"mapper.", "raster.", "metrics.", "edf.", "listen."})
    if (key.rfind(prefix, 0) == 0) return true;
  return false;
}

std::string run_key_list(std::vector<FieldGroup>& groups) {
  std::string list = "mapper.*";
  for (const FieldGroup& g : groups)
    for (const Field& f : g.fields) list += ", " + g.prefix + f.name;
  return list;
}

void apply_run_setting(RunSettings& settings, const Setting& s) {
  if (s.key.rfind("mapper.", 0) == 0) {
    settings.mapper.push_back({s.key.substr(7), s.value, s.source});
    return;
  }
  std::vector<FieldGroup> groups = run_key_fields(settings);
  for (const FieldGroup& g : groups) {
    if (s.key.rfind(g.prefix, 0) != 0) continue;
    if (const Field* f = find_field(g.fields, s.key.substr(g.prefix.size()))) {
      set_field(*f, s.key, s.value, s.source);
      settings.ghost_tolerance_set |= s.key == "metrics.ghost_tolerance";
      settings.edf_max_range_set |= s.key == "edf.max_range";
      return;
    }
  }
  throw InputError(s.source + ": unknown key '" + s.key + "' (run keys: " + run_key_list(groups) + ")");
}

// The EDF circle's rays at the centres of equal slices of the band the circle covers.
void derive_edf_settings(RunSettings& settings) {
  if (!settings.edf_max_range_set) settings.edf.max_range = settings.raster.max_range;
  const double slice =
      (settings.raster.band_max - settings.raster.band_min) / std::max(1, settings.edf_trace_rows);
  settings.edf.trace_heights.clear();
  for (int j = 0; j < settings.edf_trace_rows; ++j)
    settings.edf.trace_heights.push_back(settings.raster.band_min + (j + 0.5) * slice);
}

// The area of the scene's surfaces at the start, from the exact world triangles; recorded data
// has none, so a sphere of 5 m radius (a room around one place) stands in for it.
double surface_area(const FrameSource& source) {
  const auto truth = source.truth(0.0);
  if (!truth) return 4.0 * 3.14159265358979 * 25.0;
  double area = 0.0;
  for (const sim::WorldTriangle& t : *truth)
    area += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
  return area;
}

}  // namespace

std::vector<FieldGroup> run_key_fields(RunSettings& s) {
  FieldTable edf = {
      flag("enabled", &s.edf_enabled, "compare the map's distance field along rays (edf.csv)"),
      whole("every", &s.edf_every, 1, 1000000, "EDF comparison every n-th evaluated frame"),
      whole("trace_rows", &s.edf_trace_rows, 0, 100,
            "rays per bin across the obstacle band (0: one at the sensor's height)")};
  for (Field& f : edf_raster_fields(s.edf)) edf.push_back(std::move(f));
  return {{"raster.", raster_fields(s.raster)}, {"metrics.", metrics_fields(s.metrics)}, {"edf.", edf},
          {"listen.", listen_fields(s.listen)}};
}

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
  derive_edf_settings(settings);
  try {
    settings.edf.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--set edf.*: ") + e.what());
  }
}

nlohmann::json run_settings_json(const RunSettings& settings) {
  RunSettings copy = settings;
  nlohmann::json out = nlohmann::json::object();
  for (const FieldGroup& g : run_key_fields(copy)) {
    nlohmann::json& group = out[g.prefix.substr(0, g.prefix.size() - 1)];
    for (const Field& f : g.fields) {
      if (const double* const* d = std::get_if<double*>(&f.target)) group[f.name] = **d;
      else if (const int* const* i = std::get_if<int*>(&f.target)) group[f.name] = **i;
      else if (const bool* const* b = std::get_if<bool*>(&f.target)) group[f.name] = **b;
      else group[f.name] = field_value(f);
    }
  }
  out["edf"]["trace_heights"] = settings.edf.trace_heights;
  return out;
}

void check_memory_budget(const Mapper& mapper, const FrameSource& source, double max_memory_gib) {
  if (!(max_memory_gib >= 0.0) || max_memory_gib > 1e6)
    throw InputError("--max-memory must be a size in GiB in [0, 1000000] (0: half the RAM)");
  double budget = max_memory_gib * 1073741824.0;
  if (budget == 0.0)
    budget = 0.5 * double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  const double area = surface_area(source);
  const double estimate = estimated_map_bytes(mapper, area);
  if (estimate > budget)
    throw InputError(fmt::format(
        "the map would need about {:.3g} GiB (voxel {} m over {:.4g} m^2 of surface), more than "
        "the --max-memory budget of {:.3g} GiB; use a larger voxel or raise --max-memory",
        estimate / 1073741824.0, mapper_voxel(mapper), area, budget / 1073741824.0));
}

std::string run_keys_markdown() {
  RunSettings defaults;
  std::string text;
  for (const FieldGroup& g : run_key_fields(defaults))
    text += "\n### `" + g.prefix + "*`\n\n" + markdown_table(g.fields, g.prefix);
  return text + mapper_settings_markdown();
}

std::string run_keys_help() {
  RunSettings defaults;
  std::string text = "Run keys (--set KEY=VALUE; key = default  range  meaning):\n";
  for (const FieldGroup& g : run_key_fields(defaults)) text += help_lines(g.fields, g.prefix);
  return text + mapper_settings_help();
}

}  // namespace sonomap::harness
