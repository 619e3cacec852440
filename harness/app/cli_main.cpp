// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/cli_main.hpp"

#include "harness/app/cli.hpp"

namespace sonomap {

int cli_main(int argc, char** argv) { return harness::run_cli(argc, argv); }

}  // namespace sonomap
