// The physical floor of the spectrum's sort, for the benchmarks: one sort of as many (64-bit key,
// 32-bit value) pairs as a family's spectrum has entries, by the backend's own sort (a device
// radix sort on CUDA, Thrust's OpenMP sort on the CPU), on random keys. The whole-family time over
// this floor says how far the pipeline is from the cost of the one step it cannot avoid.
#pragma once

#include <cstddef>

#include "absl/status/statusor.h"
#include "gpu/system/backend.hpp"

namespace galpha {

/// Best of three sorts, in seconds (kAuto as the engine resolves it). Unavailable for CUDA without
/// a GPU; ResourceExhausted when the pairs do not fit.
absl::StatusOr<double> MeasureSortFloorSeconds(size_t pairs, Backend backend);

}  // namespace galpha
