// The CUDA instantiation of the engine's persistence diagram: one stream, stream-ordered memory.
#include <cuda_runtime.h>

#include "gpu/alpha/persistence_backend.hpp"
#include "gpu/alpha/persistence_pairs.cuh"
#include "gpu/system/cuda_system.cuh"

namespace galpha::detail {

void PersistenceOnCuda(const PersistenceIn& host, bool host_finish, void* stream, PersistenceOut* out) {
  RunOnCudaStream(stream, [&](CudaSystem& system) {
    PersistenceDiagramUploading(system, host, /*upload_tables=*/true, host_finish, out);
  });
}

void PersistenceOnCudaWithTables(const PersistenceIn& in, bool host_finish, void* stream, PersistenceOut* out) {
  CudaSystem system(static_cast<cudaStream_t>(stream));
  PersistenceDiagramUploading(system, in, /*upload_tables=*/false, host_finish, out);
}

}  // namespace galpha::detail
