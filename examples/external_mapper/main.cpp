// SPDX-License-Identifier: GPL-3.0-or-later
// The whole sonomap command line with one more mapper:
//   occupancy_sonomap run scene.yaml --mapper voxel_occupancy --out result
//   occupancy_sonomap compare sweep.yaml --out results   (variants may use voxel_occupancy)
#include "harness/app/cli_main.hpp"
#include "voxel_occupancy.hpp"

int main(int argc, char** argv) {
  sonomap::register_mapper("voxel_occupancy", occupancy::make_mapper);
  return sonomap::cli_main(argc, argv);
}
