// MeasureSortFloorSeconds on the CUDA backend: a device radix sort on a stream of its own.
#include "gpu/system/cuda_system.cuh"
#include "bench/sort_floor/sort_floor_impl.cuh"

namespace galpha::detail {

double SortFloorOnCuda(size_t pairs) {
  OwnedStream stream;
  CudaSystem system(stream.get());
  return SortFloorSeconds(system, pairs);
}

}  // namespace galpha::detail
