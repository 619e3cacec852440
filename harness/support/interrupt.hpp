// SPDX-License-Identifier: GPL-3.0-or-later
// SIGINT, SIGTERM, SIGHUP and SIGQUIT stop long runs cleanly: the handler only records the
// signal; loops poll it and throw Interrupted, and every staged output checks it up to the
// rename that publishes it, so unwinding removes partial outputs and keeps finished ones.
// The process then exits with 128 + the signal's number (130, 143, 129, 131), as a shell does.
#pragma once

#include <stdexcept>

namespace sonomap::harness {

class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

constexpr int kExitInterrupted = 130;  // SIGINT's; interrupt_exit_status() gives the actual one

// Idempotent; staged outputs install it when they are created.
void install_interrupt_handler();
bool interrupt_requested();
// The first signal received (0: none).
int interrupt_signal();
// 128 + the signal received (kExitInterrupted when none was).
int interrupt_exit_status();
void throw_if_interrupted();

}  // namespace sonomap::harness
