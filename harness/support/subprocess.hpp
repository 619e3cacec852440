// SPDX-License-Identifier: GPL-3.0-or-later
// Running helper programs (gnuplot) without a shell, so paths with spaces or quotes are safe.
#pragma once

#include <string>
#include <vector>

namespace sonomap::harness {

// Runs argv[0] (looked up in PATH) with the given arguments, stdout and stderr captured into
// `output`. Returns the exit status, or -1 when the program could not be started.
int run_program(const std::vector<std::string>& argv, std::string* output = nullptr);

// Runs argv[0] (looked up in PATH) with stdin from /dev/null and stdout/stderr inherited, in
// its own process group. Past `timeout_s` seconds, or on Ctrl-C (interrupt.hpp), the whole
// group is killed. Returns the exit status (128 + signal when killed by one), -1 when the
// program could not be started; `timed_out` tells whether the time limit ended it.
int run_program_with_timeout(const std::vector<std::string>& argv, double timeout_s, bool& timed_out);

}  // namespace sonomap::harness
