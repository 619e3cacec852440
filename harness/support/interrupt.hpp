// SPDX-License-Identifier: GPL-3.0-or-later
// Ctrl-C (SIGINT) and SIGTERM stop long runs cleanly: the handler only sets a flag; loops poll
// it and throw Interrupted, so unwinding removes partial outputs and keeps finished ones.
#pragma once

#include <stdexcept>

namespace sonomap::harness {

class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

constexpr int kExitInterrupted = 130;

void install_interrupt_handler();
bool interrupt_requested();
void throw_if_interrupted();

}  // namespace sonomap::harness
