// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/cli_main.hpp"

int main(int argc, char** argv) { return sonomap::cli_main(argc, argv); }
