// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/cli.hpp"

int main(int argc, char** argv) { return sonomap::harness::run_cli(argc, argv); }
