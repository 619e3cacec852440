// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/mapper_factory.hpp"

#include "core/depth_only.hpp"
#include "core/open3d_tsdf.hpp"
#include "harness/app/config_fields.hpp"
#include "harness/formats/modules.hpp"
#include "harness/support/errors.hpp"

#include <cmath>
#include <cstdlib>

namespace sonomap::harness {
namespace {

void apply(const FieldTable& table, const std::string& mapper, const std::vector<Setting>& settings) {
  for (const Setting& s : settings) {
    const Field* field = find_field(table, s.key);
    if (!field)
      throw InputError(s.source + ": mapper '" + mapper + "' has no setting '" + s.key +
                       "' (settings: " + (table.empty() ? "none" : field_names(table)) + ")");
    set_field(*field, "mapper." + s.key, s.value, s.source);
  }
}

// The factories. A config's own validation throws std::invalid_argument, which make_mapper()
// reports as bad input naming the mapper.
// --voxel (when > 0) sets VDB-GPDF's global voxel and scales the per-frame geometry with it:
// the local grid, the GP lengthscale and where carving starts stay the same number of voxels
// (2 cm, 3.3 cm and 5 cm at 5 cm), so a coarser map costs less per frame (at 10 cm a fixed
// 2 cm local grid cost 90% of the 5 cm frame). The query step stays 5 cm: at 10 cm, steps
// of 10 cm gave the room's circle and cylinder more error than 5 cm steps (mean RMSE 0.065 vs
// 0.049 m and 0.234 vs 0.203 m, 150 frames).
void set_voxel_scaling_frame_geometry(double voxel, VdbGpdfConfig& c) {
  if (voxel <= 0) return;
  const double scale = voxel / c.global_voxel;
  c.local_voxel *= scale;
  c.lambda /= scale * scale;
  c.carving_step *= scale;
  c.global_voxel = voxel;
}

std::unique_ptr<Mapper> make_vdb_gpdf(double voxel, const std::vector<Setting>& settings) {
  VdbGpdfConfig c;
  set_voxel_scaling_frame_geometry(voxel, c);
  apply(vdb_gpdf_fields(c), "vdb_gpdf", settings);
  return std::make_unique<VdbGpdf>(c);
}

// --voxel (when > 0) sets a TSDF's voxel size and keeps its truncation at the same number of voxels.
void set_voxel_keeping_truncation(double voxel, double& size, double& truncation) {
  if (voxel <= 0) return;
  truncation *= voxel / size;
  size = voxel;
}

std::unique_ptr<Mapper> make_tsdf(double voxel, const std::vector<Setting>& settings) {
  TsdfConfig c;
  set_voxel_keeping_truncation(voxel, c.voxel, c.truncation);
  apply(tsdf_fields(c), "tsdf", settings);
  return std::make_unique<Tsdf>(c);
}

// Open3D's ScalableTSDFVolume with the TSDF peer's voxel and truncation (and the same rule
// for --voxel), so A/B runs against the reference compare like with like.
Open3dTsdfConfig open3d_defaults() {
  const TsdfConfig peer;
  Open3dTsdfConfig c;
  c.voxel = peer.voxel;
  c.truncation = peer.truncation;
  c.min_range = peer.min_range;
  c.max_range = peer.max_range;
  return c;
}

std::unique_ptr<Mapper> make_open3d(double voxel, const std::vector<Setting>& settings) {
  Open3dTsdfConfig c = open3d_defaults();
  set_voxel_keeping_truncation(voxel, c.voxel, c.truncation);
  apply(open3d_fields(c), "open3d", settings);
  return open3d_functions().make_mapper(c);
}

// The open3d mapper's settings. Its class (and its type information) is in the module loaded
// on demand; asking by name first keeps the module unloaded in runs of the other mappers.
const Open3dTsdfConfig* open3d_config(const Mapper& mapper) {
  return mapper.name() == "open3d" ? open3d_functions().config_of(mapper) : nullptr;
}

// Calls `use(name, table)` with each mapper's table over a config of its defaults.
template <typename Use>
void for_each_default_table(Use use) {
  VdbGpdfConfig vdb;
  use("vdb_gpdf", vdb_gpdf_fields(vdb));
  TsdfConfig tsdf;
  use("tsdf", tsdf_fields(tsdf));
  Open3dTsdfConfig open3d = open3d_defaults();
  use("open3d", open3d_fields(open3d));
}

}  // namespace

std::vector<std::pair<std::string, MapperFactory>> builtin_mappers() {
  const auto depth_only = [](double, const std::vector<Setting>& settings) -> std::unique_ptr<Mapper> {
    apply({}, "depth_only", settings);
    return std::make_unique<DepthOnlyMapper>();
  };
  return {{"vdb_gpdf", make_vdb_gpdf},
          {"tsdf", make_tsdf},
          {"open3d", make_open3d},
          {"depth_only", depth_only}};
}

std::vector<std::pair<std::string, std::string>> mapper_config_entries(const Mapper& mapper) {
  std::vector<std::pair<std::string, std::string>> entries{{"mapper", mapper.name()}};
  const auto add = [&](const FieldTable& table) {
    for (const Field& f : table) entries.emplace_back(f.name, field_value(f));
  };
  if (const auto* v = dynamic_cast<const VdbGpdf*>(&mapper)) {
    VdbGpdfConfig c = v->config();
    add(vdb_gpdf_fields(c));
  } else if (const auto* t = dynamic_cast<const Tsdf*>(&mapper)) {
    TsdfConfig c = t->config();
    add(tsdf_fields(c));
  } else if (const auto* o = open3d_config(mapper)) {
    Open3dTsdfConfig c = *o;
    add(open3d_fields(c));
  } else {
    for (const auto& entry : mapper.config_entries()) entries.push_back(entry);  // registered
  }
  return entries;
}

double mapper_voxel(const Mapper& mapper) {
  if (const auto* v = dynamic_cast<const VdbGpdf*>(&mapper)) return v->config().global_voxel;
  if (const auto* t = dynamic_cast<const Tsdf*>(&mapper)) return t->config().voxel;
  if (const auto* o = open3d_config(mapper)) return o->voxel;
  for (const auto& [key, value] : mapper.config_entries()) {  // a registered mapper
    char* end = nullptr;
    const double voxel = key == "voxel" ? std::strtod(value.c_str(), &end) : 0.0;
    if (end && *end == '\0' && std::isfinite(voxel) && voxel > 0.0) return voxel;
  }
  return 0.0;
}

double estimated_map_bytes(const Mapper& mapper, double surface_area) {
  const double voxel = mapper_voxel(mapper);
  if (voxel <= 0.0) return 0.0;
  const double leaf_side = 8.0 * voxel;
  const double leaves = 2.0 * surface_area / (leaf_side * leaf_side);
  const double leaf_bytes = 512.0 * 8.0 + 128.0;  // (distance, weight) floats and masks
  return leaves * leaf_bytes;
}

std::string mapper_settings_markdown() {
  std::string text;
  for_each_default_table([&](const std::string& name, const FieldTable& table) {
    text += "\n### Mapper `" + name + "`\n\n" + markdown_table(table, "mapper.");
  });
  return text;
}

std::string mapper_settings_help() {
  std::string text;
  for_each_default_table([&](const std::string& name, const FieldTable& table) {
    text += "Mapper settings of " + name + " (--set mapper.FIELD=VALUE):\n" + help_lines(table, "mapper.");
  });
  return text;
}

}  // namespace sonomap::harness
