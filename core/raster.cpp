// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/raster.hpp"

#include <cmath>

namespace sonomap {

int RasterConfig::rows() const {
  // Rows of row_height over the band; a tiny epsilon so 1.9 / 0.1 gives 19, not 18.999.
  return static_cast<int>(std::floor((band_max - band_min) / row_height + 1e-9));
}

}  // namespace sonomap
