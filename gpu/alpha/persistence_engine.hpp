// The persistence diagram of a built family (core/family/persistence.hpp defines it) computed by
// the engine's backend: the canonical orders, both spanning forests and the elder rule in parallel
// on CUDA or OpenMP (persistence_pairs.cuh), the same diagram, pair for pair, as the host's
// union-finds. docs/topology.md, "How the diagram is computed".
#pragma once

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "core/family/persistence.hpp"
#include "gpu/alpha/persistence_report.hpp"
#include "gpu/system/backend.hpp"

namespace galpha {

struct PersistenceOptions {
  Backend backend = Backend::kAuto;
  /// CUDA stream (a cudaStream_t) to run on; nullptr: one of the engine's own.
  void* cuda_stream = nullptr;
  /// Pair the forests' slow tails on the host (what is left once a parallel round contracts less
  /// than an eighth of the live edges, or fewer than 1024 are left). False runs every round on the
  /// backend, however many (tests use it to exercise the rounds on small inputs).
  bool host_finish = true;
};

/// The diagram, with the stages' times and the forests' rounds in `report` when not null. Internal
/// error if the family contradicts planar duality; Unavailable for CUDA in a build without it.
absl::StatusOr<PersistenceDiagram> ComputePersistenceOnBackend(const AlphaFamily& family,
                                                               const PersistenceOptions& options = {},
                                                               PersistenceReport* report = nullptr);

/// The diagram front ends answer with: the family's own when its build computed it
/// (BuildOptions::persistence); else the engine's on CUDA when the family was built there and
/// CUDA is here (unless the device is out of memory); else the host's (ComputePersistence), with
/// the canonical orders when the caller keeps them (empty spans: computed here). The same diagram
/// whichever way.
absl::StatusOr<PersistenceDiagram> PersistenceDiagramOf(const AlphaFamily& family,
                                                        absl::Span<const uint32_t> edge_order = {},
                                                        absl::Span<const uint32_t> triangle_order = {});

}  // namespace galpha
