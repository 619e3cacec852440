// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/raster.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace sonomap {

namespace {

// Rows of row_height over the band; a tiny epsilon so 1.9 / 0.1 gives 19, not 18.999. In
// doubles, so that validate() can bound a tiny row height's count before it is an int.
double row_count(const RasterConfig& c) {
  return std::floor((c.band_max - c.band_min) / c.row_height + 1e-9);
}

}  // namespace

int RasterConfig::rows() const { return static_cast<int>(row_count(*this)); }

void RasterConfig::validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("raster config: " + what);
  };
  if (azimuth_bins < 1 || azimuth_bins > 36000) {
    fail("azimuth_bins must be in [1, 36000], got " + std::to_string(azimuth_bins));
  }
  if (!std::isfinite(band_min) || !std::isfinite(band_max)) fail("band_min/band_max must be finite");
  if (!(band_min < band_max)) {
    fail("band_min (" + std::to_string(band_min) + ") must be below band_max (" +
         std::to_string(band_max) + ")");
  }
  if (!std::isfinite(row_height) || !(row_height > 0.0)) fail("row_height must be > 0");
  const double rows_in_band = row_count(*this);
  if (rows_in_band < 1.0) fail("row_height is taller than the band: no cylinder row fits");
  if (rows_in_band * azimuth_bins > kMaxCylinderCells) {
    std::ostringstream what;
    what << "row_height " << row_height << " m with " << azimuth_bins << " azimuth_bins makes a cylinder of "
         << rows_in_band * azimuth_bins << " cells, more than " << kMaxCylinderCells << "; raise row_height";
    fail(what.str());
  }
  if (!std::isfinite(max_range) || !(max_range > 0.0)) fail("max_range must be > 0");
}

int Circle::known_count() const {
  return static_cast<int>(
      std::count_if(bins.begin(), bins.end(), [](const RasterCell& c) { return c.known(); }));
}

void Circle::clear() { std::fill(bins.begin(), bins.end(), RasterCell{}); }

int Cylinder::known_count() const {
  return static_cast<int>(
      std::count_if(cells.begin(), cells.end(), [](const RasterCell& c) { return c.known(); }));
}

void Cylinder::clear() { std::fill(cells.begin(), cells.end(), RasterCell{}); }

Circle make_circle(const RasterConfig& config) {
  config.validate();
  return Circle(config.azimuth_bins);
}

Cylinder make_cylinder(const RasterConfig& config) {
  config.validate();
  return Cylinder(config.azimuth_bins, config.rows());
}

std::vector<Sector> circle_sectors(const Circle& circle, int sector_count) {
  if (sector_count <= 0 || circle.size() == 0 || circle.size() % sector_count != 0) {
    throw std::invalid_argument("circle_sectors: " + std::to_string(sector_count) +
                                " sectors do not divide a circle of " +
                                std::to_string(circle.size()) + " bins");
  }
  const int per_sector = circle.size() / sector_count;
  std::vector<Sector> sectors(static_cast<size_t>(sector_count));
  for (int s = 0; s < sector_count; ++s) {
    Sector& sector = sectors[static_cast<size_t>(s)];
    for (int bin = s * per_sector; bin < (s + 1) * per_sector; ++bin) {
      const RasterCell& cell = circle.bins[static_cast<size_t>(bin)];
      if (cell.range < sector.range) {  // strict: ties keep the lowest bin
        sector.range = cell.range;
        sector.bin = bin;
        sector.angle_deg = circle.bin_centre_deg(bin);
        sector.point = cell.point;
      }
    }
  }
  return sectors;
}

}  // namespace sonomap
