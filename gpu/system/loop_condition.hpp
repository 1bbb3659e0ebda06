// The condition of a loop that runs on the device without the host (System::ReplayWhile), shared by
// both systems so that they stop at the same run.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"

namespace galpha::detail {

/// After each run of a loop's body: whether to run it again, that is while `*count` is nonzero,
/// at most `max_runs` runs a loop. `*runs` counts the runs of the loop under way (zero between
/// loops: it is reset when the loop ends); a loop that the cap ended with `*count` still nonzero
/// sets `*capped`, which the caller reads later with its other flags.
struct WhileCountNonzero {
  const uint32_t* count;
  uint32_t* runs;
  uint32_t max_runs;
  int32_t* capped;

  GALPHA_HD bool operator()() const {
    const bool more = *count != 0;
    const uint32_t done = *runs + 1;
    if (more && done < max_runs) {
      *runs = done;
      return true;
    }
    *runs = 0;
    if (more) *capped = 1;
    return false;
  }
};

}  // namespace galpha::detail
