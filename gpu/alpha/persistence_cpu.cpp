// The OpenMP instantiation of the engine's persistence diagram.
#include "gpu/alpha/persistence_backend.hpp"
#include "gpu/alpha/persistence_pairs.cuh"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

void PersistenceOnCpu(const PersistenceIn& host, bool host_finish, PersistenceOut* out) {
  CpuSystem system;
  PersistenceDiagramUploading(system, host, /*upload_tables=*/true, host_finish, out);
}

}  // namespace galpha::detail
