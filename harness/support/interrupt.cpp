// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/support/interrupt.hpp"

#include <csignal>

namespace sonomap::harness {
namespace {
volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_signal(int signal) {
  if (g_signal == 0) g_signal = signal;
}
}  // namespace

void install_interrupt_handler() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking wait (compare's waitpid) sees EINTR
  for (int signal : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaction(signal, &action, nullptr);
}

bool interrupt_requested() { return g_signal != 0; }

int interrupt_signal() { return g_signal; }

int interrupt_exit_status() { return g_signal != 0 ? 128 + g_signal : kExitInterrupted; }

void throw_if_interrupted() {
  if (g_signal != 0) throw Interrupted();
}

}  // namespace sonomap::harness
