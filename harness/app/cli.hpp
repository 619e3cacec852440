// SPDX-License-Identifier: GPL-3.0-or-later
// The `sonomap` command line: a thin layer over harness functions that tests can call.
#pragma once

#include "harness/support/version.hpp"

#include <CLI/CLI.hpp>
#include <string>

namespace sonomap::harness {

// Options every command understands.
struct GlobalOptions {
  bool quiet = false;  // no progress bar, no summary screen
  int threads = 0;     // 0: all cores
};

// Each command lives in its own source file and registers itself here.
// The callback it sets runs after parsing; it throws InputError for bad input.
// (one line per command: add yours here and in run_cli)
void add_run_command(CLI::App& app, const GlobalOptions& global);
void add_compare_command(CLI::App& app, const GlobalOptions& global);
void add_report_command(CLI::App& app, const GlobalOptions& global);
void add_render_command(CLI::App& app, const GlobalOptions& global);
void add_brir_command(CLI::App& app, const GlobalOptions& global);
void add_sonify_command(CLI::App& app, const GlobalOptions& global);
void add_bench_command(CLI::App& app, const GlobalOptions& global);
void add_score_command(CLI::App& app, const GlobalOptions& global);
void add_diff_command(CLI::App& app, const GlobalOptions& global);
void add_keys_command(CLI::App& app, const GlobalOptions& global);
// The key reference `sonomap keys` prints (docs/settings.md holds it).
std::string key_reference_markdown();

// Parses argv and runs the chosen command. Returns the process exit status:
// 0 success, 2 bad input (message names file, line and key), 1 other failure.
int run_cli(int argc, char** argv);


}  // namespace sonomap::harness
