// SPDX-License-Identifier: GPL-3.0-or-later
// Running helper programs (gnuplot) without a shell, so paths with spaces or quotes are safe.
#pragma once

#include <string>
#include <vector>

namespace sonomap::harness {

// Runs argv[0] (looked up in PATH) with the given arguments, stdout and stderr captured into
// `output`. Returns the exit status, or -1 when the program could not be started.
int run_program(const std::vector<std::string>& argv, std::string* output = nullptr);

}  // namespace sonomap::harness
