// SPDX-License-Identifier: GPL-3.0-or-later
// The whole `sonomap` command line for a program of your own: register your mapper, then hand
// over argv. See docs/sdk.md.
//
//   int main(int argc, char** argv) {
//     sonomap::register_mapper("mine", make_my_mapper);
//     return sonomap::cli_main(argc, argv);
//   }
#pragma once

#include "harness/app/mapper_registry.hpp"

namespace sonomap {

// Parses argv and runs the chosen command (run, compare, score, report, bench, ...), exactly as
// the `sonomap` program does. Returns the process exit status: 0 success, 2 bad input (the
// message names the file, line and key, or the frame and value), 1 any other failure.
// `compare` runs its jobs by starting this same program again, so register mappers
// unconditionally at the start of main(), before cli_main().
int cli_main(int argc, char** argv);

}  // namespace sonomap
