// SPDX-License-Identifier: GPL-3.0-or-later
// Parallel loops over TBB. Each task writes only its own data, so results do not depend on
// the thread count.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <cstddef>

namespace sonomap {

// f(i) for i in [0, n).
template <typename F>
void parallel_for_each_index(std::size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}

// a() and b() at once, for two serial steps that write disjoint data.
template <typename A, typename B>
void parallel_both(A&& a, B&& b) {
  tbb::parallel_invoke(a, b);
}

}  // namespace sonomap
