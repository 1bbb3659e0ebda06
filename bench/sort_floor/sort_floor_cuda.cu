// MeasureSortFloorSeconds on the CUDA backend: a device radix sort on a stream of its own.
#include "bench/sort_floor/sort_floor_impl.cuh"
#include "gpu/system/cuda_system.cuh"

namespace galpha::detail {

double SortFloorOnCuda(size_t pairs) {
  OwnedStream stream;
  CudaSystem system(stream.get());
  return SortFloorSeconds(system, pairs);
}

}  // namespace galpha::detail
