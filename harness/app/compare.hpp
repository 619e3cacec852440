// SPDX-License-Identifier: GPL-3.0-or-later
// A/B comparisons: a sweep file names scenarios, mapper variants, seeds and overrides; every
// combination is an independent `sonomap run` with its own result directory. Computing and
// comparing stay separate: `compare` runs the jobs (or emits them as a job list for a cluster
// scheduler) and then `report` rolls up whatever result directories exist.
//
// Sweep file (YAML; paths relative to it):
//   name: paper                       # required
//   frames: 300                       # optional, every run (else the scenario's)
//   every: 5                          # optional: evaluate every K-th frame
//   seeds: [1, 2]                     # optional, default [1]
//   set: [sensor.noise.model=kinect]  # optional overrides for every run
//   scenarios:                        # required
//     - {id: room, file: room.yaml, frames: 600, set: [...]}
//   variants:                         # required
//     - {id: gpdf_5cm, mapper: vdb_gpdf, voxel: 0.05, set: [mapper.carving=false]}
//     - {id: mine, command: "python3 my_mapper.py {sequence} {out}", timeout: 300}
//       # an external mapper (score.hpp): run on the scenario rendered as a TUM sequence
//       # ({sequence}, cached under <out>/sequences), it writes {out}/circle.csv (and optionally
//       # cylinder.csv); {frames} is the frame count. No shell; timeout in seconds (default 600).
//   pictures: [-1]                    # optional, passed to run --pictures
//   sweeps: [-1]                      # optional, passed to run --sweeps
//   claims: [...]                     # optional: the paper's figures to check (claims.hpp)
//   gates:                            # optional: CI gates; report and compare exit 1 if one fails
//     - {scenario: room, variant: gpdf_5cm, metric: circle_mean_rmse, op: "<=", value: 0.1}
#pragma once

#include "harness/app/cli.hpp"
#include "harness/report/claims.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::harness {

struct Job {
  std::string id;                 // "<scenario>-<variant>-s<seed>", also the run directory name
  std::vector<std::string> args;  // sonomap arguments after the program name
};

struct Sweep {
  std::string name;
  std::vector<Job> jobs;
  std::vector<Claim> claims;
  std::vector<Claim> gates;
};

// Parses and validates a sweep file; job outputs go to <out>/runs/<id>.
// Errors are InputErrors naming the file, line and key.
Sweep load_sweep(const std::filesystem::path& file, const std::filesystem::path& out);

// One shell-quoted command line per job (for GNU parallel, a Slurm array, ...).
std::string job_list(const Sweep& sweep, const std::string& program);

void add_compare_command(CLI::App& app, const GlobalOptions& global);

}  // namespace sonomap::harness
