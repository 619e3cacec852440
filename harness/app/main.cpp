// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/cli.hpp"

#include <malloc.h>

int main(int argc, char** argv) {
  // A frame's large buffers (ray hits, depth images, points: about 15 MB at 640x480) are
  // allocated and freed every frame. With glibc's defaults they are mmapped and unmapped each
  // time, and every page faults again on first touch (measured: ~0.5 ms per MB, more than the
  // noise model's arithmetic). Keep up to 64 MB of freed memory in the heap for reuse instead.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  return sonomap::harness::run_cli(argc, argv);
}
