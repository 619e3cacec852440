// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/cli.hpp"

#include "harness/support/errors.hpp"
#include "harness/support/interrupt.hpp"

#include <cstdio>
#include <memory>
#include <tbb/global_control.h>

namespace sonomap::harness {

int run_cli(int argc, char** argv) {
  CLI::App app{"sonomap: depth sensing -> online map -> 360-degree rasters -> binaural sound"};
  app.require_subcommand(1);
  app.fallthrough();  // --quiet and --threads work after the command name too
  // Every command's --help shows every default (subcommands inherit this).
  app.option_defaults()->always_capture_default();
  app.set_version_flag("--version", code_version());
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No progress bar and no summary screen");
  app.add_option("--threads", global.threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 4096));
  std::unique_ptr<tbb::global_control> thread_limit;
  app.parse_complete_callback([&] {
    if (global.threads > 0)
      thread_limit = std::make_unique<tbb::global_control>(
          tbb::global_control::max_allowed_parallelism, global.threads);
  });

  // Commands: one line each (declared in cli.hpp).
  add_run_command(app, global);
  add_compare_command(app, global);
  add_report_command(app, global);
  add_render_command(app, global);
  add_brir_command(app, global);
  add_sonify_command(app, global);
  add_bench_command(app, global);
  add_score_command(app, global);
  add_diff_command(app, global);
  add_keys_command(app, global);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command's own status (e.g. some runs of a sweep failed)
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  } catch (const InputError& e) {
    std::fprintf(stderr, "sonomap: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const Interrupted&) {
    std::fprintf(stderr, "sonomap: interrupted; partial output removed\n");
    return interrupt_exit_status();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sonomap: failure: %s\n", e.what());
    return kExitFailure;
  }
  if (interrupt_requested()) {  // after the last check: the output was already whole
    std::fprintf(stderr, "sonomap: interrupted after the output was complete; it is kept\n");
    return interrupt_exit_status();
  }
  return 0;
}

}  // namespace sonomap::harness
