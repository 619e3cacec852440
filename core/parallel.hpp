// SPDX-License-Identifier: GPL-3.0-or-later
// f(i) for i in [0, n) over TBB. Each index writes only its own slot, so results do not
// depend on the thread count.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace sonomap {

template <typename F>
void parallel_for_each_index(std::size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}

}  // namespace sonomap
