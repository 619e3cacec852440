// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/cli_main.hpp"

#include "harness/app/cli.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sonomap {

namespace {

// A run maps frame after frame, and each frame allocates and frees the same scratch (point
// sums, votes, local GPs: tens of MB at 5 cm). By default glibc hands freed memory back to the
// kernel (it trims the heap's top and unmaps large blocks), and the next frame faults every
// page in again, zero-filled: on the 2-core test machine about 1,000 page faults and 6 ms of
// kernel time a 5 cm room frame on one thread (docs/performance.md, "Freed memory kept, and
// every group warmed up"). As real-time Linux programs do, the process keeps what it freed for
// the next frame: no trimming, no blocks of their own mapping. The peak RSS barely moves (a
// frame's scratch is part of the peak anyway; the 2700-frame room 141 MB instead of 135); the
// memory goes back at exit.
void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_TRIM_THRESHOLD, -1);  // read as the largest size: never trim
  mallopt(M_MMAP_MAX, 0);         // every block from the heap, none mapped (and unmapped) alone
#endif
}

}  // namespace

int cli_main(int argc, char** argv) {
  keep_freed_memory();
  return harness::run_cli(argc, argv);
}

}  // namespace sonomap
