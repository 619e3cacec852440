// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/interrupt.hpp"

#include <csignal>

namespace sonomap::harness {
namespace {
volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_signal(int) { g_interrupted = 1; }
}  // namespace

void install_interrupt_handler() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool interrupt_requested() { return g_interrupted != 0; }

void throw_if_interrupted() {
  if (g_interrupted) throw Interrupted();
}

}  // namespace sonomap::harness
