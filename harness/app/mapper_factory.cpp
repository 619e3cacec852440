// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/mapper_factory.hpp"

#include "core/depth_only.hpp"
#include "core/open3d_tsdf.hpp"
#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "harness/support/errors.hpp"

#include <cmath>
#include <map>
#include <stdexcept>
#include <variant>

namespace sonomap::harness {
namespace {

// The settable fields of one mapper's config, by the name users write after "mapper.".
using FieldRef = std::variant<double*, int*, bool*>;
using FieldTable = std::map<std::string, FieldRef>;

std::string field_list(const FieldTable& table) {
  std::string names;
  for (const auto& entry : table) names += (names.empty() ? "" : ", ") + entry.first;
  return names;
}

void apply(const FieldTable& table, const std::string& mapper, const Setting& s) {
  const auto it = table.find(s.key);
  if (it == table.end())
    throw InputError(s.source + ": mapper '" + mapper + "' has no setting '" + s.key +
                     "' (settings: " + field_list(table) + ")");
  const auto bad = [&](const char* expected) {
    return InputError(s.source + ": key 'mapper." + s.key + "': expected " + expected + ", got '" +
                      s.value + "'");
  };
  std::visit(
      [&](auto* field) {
        using T = std::remove_pointer_t<decltype(field)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (s.value == "true" || s.value == "on" || s.value == "1") *field = true;
          else if (s.value == "false" || s.value == "off" || s.value == "0") *field = false;
          else throw bad("true or false");
        } else {
          size_t used = 0;
          double v = 0;
          try {
            v = std::stod(s.value, &used);
          } catch (const std::exception&) {
            throw bad("a number");
          }
          if (used != s.value.size() || !std::isfinite(v)) throw bad("a number");
          if constexpr (std::is_same_v<T, int>) {
            if (v != std::floor(v) || std::abs(v) > 1e9) throw bad("a whole number");
            *field = static_cast<int>(v);
          } else {
            *field = v;
          }
        }
      },
      it->second);
}

// Runs the mapper's own validation and reports its message as bad input.
template <typename Make>
std::unique_ptr<Mapper> checked(const std::string& mapper, Make make) {
  try {
    return make();
  } catch (const std::invalid_argument& e) {
    throw InputError("mapper '" + mapper + "': " + e.what());
  }
}

std::unique_ptr<Mapper> make_vdb_gpdf(double voxel, const std::vector<Setting>& settings) {
  VdbGpdfConfig c;
  if (voxel > 0) c.global_voxel = voxel;
  FieldTable table{{"local_voxel", &c.local_voxel},
                   {"voxel_downsample", &c.voxel_downsample},
                   {"voxel", &c.global_voxel},
                   {"global_voxel", &c.global_voxel},
                   {"lambda", &c.lambda},
                   {"map_noise", &c.map_noise},
                   {"query_step", &c.query_step},
                   {"trunc_behind", &c.trunc_behind},
                   {"trunc_front", &c.trunc_front},
                   {"carving", &c.free_space_carving},
                   {"carving_step", &c.carving_step},
                   {"variance_cap", &c.variance_cap},
                   {"inverse_variance_fusion", &c.inverse_variance_fusion},
                   {"weight_cap", &c.weight_cap},
                   {"g_gpdf_min_touched", &c.g_gpdf_min_touched},
                   {"smooth_min", &c.smooth_min},
                   {"global_neighbours", &c.global_neighbours},
                   {"recon_min_weight", &c.recon_min_weight},
                   {"min_range", &c.min_range},
                   {"max_range", &c.max_range}};
  bool log_gpis = c.kernel == GpKernel::LogGpisMatern32;
  table["log_gpis"] = &log_gpis;
  for (const Setting& s : settings) apply(table, "vdb_gpdf", s);
  c.kernel = log_gpis ? GpKernel::LogGpisMatern32 : GpKernel::RevertingSE;
  return checked("vdb_gpdf", [&] { return std::make_unique<VdbGpdf>(c); });
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
  FieldTable table{{"voxel", &c.voxel},           {"truncation", &c.truncation},
                   {"carving", &c.space_carving}, {"weight_cap", &c.weight_cap},
                   {"min_weight", &c.min_weight}, {"min_range", &c.min_range},
                   {"max_range", &c.max_range}};
  for (const Setting& s : settings) apply(table, "tsdf", s);
  return checked("tsdf", [&] { return std::make_unique<Tsdf>(c); });
}

// Open3D's ScalableTSDFVolume with the TSDF peer's voxel and truncation (and the same rule
// for --voxel), so A/B runs against the reference compare like with like.
std::unique_ptr<Mapper> make_open3d(double voxel, const std::vector<Setting>& settings) {
  const TsdfConfig peer;
  Open3dTsdfConfig c;
  c.voxel = peer.voxel;
  c.truncation = peer.truncation;
  c.min_range = peer.min_range;
  c.max_range = peer.max_range;
  set_voxel_keeping_truncation(voxel, c.voxel, c.truncation);
  FieldTable table{{"voxel", &c.voxel},
                   {"truncation", &c.truncation},
                   {"min_range", &c.min_range},
                   {"max_range", &c.max_range}};
  for (const Setting& s : settings) apply(table, "open3d", s);
  return checked("open3d", [&] { return std::make_unique<Open3dTsdf>(c); });
}

std::unique_ptr<Mapper> make_depth_only(const std::vector<Setting>& settings) {
  for (const Setting& s : settings) apply({}, "depth_only", s);
  return std::make_unique<DepthOnlyMapper>();
}

}  // namespace

std::vector<std::string> mapper_names() { return {"vdb_gpdf", "tsdf", "open3d", "depth_only"}; }

std::unique_ptr<Mapper> make_mapper(const std::string& name, double voxel,
                                    const std::vector<Setting>& settings) {
  if (voxel < 0 || !std::isfinite(voxel))
    throw InputError("--voxel must be a positive size in metres, got " + std::to_string(voxel));
  if (name == "vdb_gpdf") return make_vdb_gpdf(voxel, settings);
  if (name == "tsdf") return make_tsdf(voxel, settings);
  if (name == "open3d") return make_open3d(voxel, settings);
  if (name == "depth_only") return make_depth_only(settings);
  std::string names;
  for (const auto& n : mapper_names()) names += (names.empty() ? "" : ", ") + n;
  throw InputError("--mapper " + name + ": unknown mapper (known: " + names + ")");
}

}  // namespace sonomap::harness
