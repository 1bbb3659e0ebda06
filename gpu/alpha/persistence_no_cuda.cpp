// Builds without nvcc have no CUDA backend: this is the persistence diagram's answer there.
#include "gpu/alpha/persistence_backend.hpp"
#include "gpu/system/backend.hpp"

namespace galpha::detail {

void PersistenceOnCuda(const PersistenceIn&, bool, void*, PersistenceOut*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

void PersistenceOnCudaWithTables(const PersistenceIn&, bool, void*, PersistenceOut*) {
  throw EngineError(EngineError::Kind::kUnavailable, "this build of galpha has no CUDA backend");
}

}  // namespace galpha::detail
