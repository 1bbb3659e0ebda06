// The engine's persistence diagram on one backend (persistence_pairs.cuh), behind the public call
// in persistence_engine.hpp. Both throw EngineError (or a Thrust/std exception) on failure.
#pragma once

namespace galpha::detail {

struct PersistenceIn;
struct PersistenceOut;

/// On the OpenMP backend, reading the family's host arrays in place.
void PersistenceOnCpu(const PersistenceIn& host, bool host_finish, PersistenceOut* out);

/// On the CUDA backend, on `stream` (a cudaStream_t, or nullptr for one of its own), after
/// uploading the arrays.
void PersistenceOnCuda(const PersistenceIn& host, bool host_finish, void* stream, PersistenceOut* out);

/// On the CUDA backend, on `stream`, for a family whose tables are in device memory already (a
/// resident family's): `in`'s edge triangles and rank tables are device pointers, its mesh (edges,
/// triangles, representatives, hidden flags) host pointers, and only the mesh is uploaded.
void PersistenceOnCudaWithTables(const PersistenceIn& in, bool host_finish, void* stream, PersistenceOut* out);

}  // namespace galpha::detail
