// SPDX-License-Identifier: GPL-3.0-or-later
// The field tables of the run's config structs: every mapper setting (`mapper.*`) and every run
// key (`raster.*`, `metrics.*`, `edf.*`) declared once, with unit, bounds and doc. `--set`,
// summary.json, `--help` and docs/settings.md all read these tables (harness/support/fields.hpp).
#pragma once

#include "core/edf_raster.hpp"
#include "core/open3d_tsdf.hpp"
#include "core/raster.hpp"
#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "eval/metrics.hpp"
#include "harness/support/fields.hpp"

namespace sonomap::harness {

FieldTable vdb_gpdf_fields(VdbGpdfConfig& c);
FieldTable tsdf_fields(TsdfConfig& c);
FieldTable open3d_fields(Open3dTsdfConfig& c);
FieldTable raster_fields(RasterConfig& c);
FieldTable metrics_fields(eval::MetricsConfig& c);
FieldTable edf_raster_fields(EdfRasterConfig& c);
struct ListenSettings;
FieldTable listen_fields(ListenSettings& c);

}  // namespace sonomap::harness
