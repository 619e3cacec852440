// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap keys`: the key reference (every scenario key, run key and mapper setting with its
// default, bounds and meaning), printed from the same tables that read them. docs/settings.md
// holds this output between its "generated" markers (a test keeps the two equal).
#include "harness/app/cli.hpp"
#include "harness/app/run_settings.hpp"
#include "harness/formats/scenario_keys.hpp"

#include <cstdio>

namespace sonomap::harness {

std::string key_reference_markdown() {
  return "## Scenario keys (numbers)\n\n" + scenario_keys_markdown() + "\n## Run keys\n" +
         run_keys_markdown();
}

void add_keys_command(CLI::App& app, const GlobalOptions&) {
  CLI::App* cmd = app.add_subcommand(
      "keys", "Print every scenario key, run key (--set) and mapper setting with its default, "
              "bounds and meaning (markdown; docs/settings.md)");
  cmd->callback([] { std::fputs(key_reference_markdown().c_str(), stdout); });
}

}  // namespace sonomap::harness
