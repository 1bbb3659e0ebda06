#include "gpu/alpha/persistence_engine.hpp"

#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "gpu/alpha/persistence_backend.hpp"
#include "gpu/alpha/persistence_pairs.cuh"
#include "gpu/system/engine_status.hpp"

namespace galpha {

absl::StatusOr<PersistenceDiagram> ComputePersistenceOnBackend(const AlphaFamily& family,
                                                               const PersistenceOptions& options,
                                                               PersistenceReport* report) {
  GALPHA_ASSIGN_OR_RETURN(const Backend backend, detail::ResolveBackend(options.backend));
  const AlphaRanks& r = family.ranks();
  // The family's host arrays as the engine's types (the same layouts: two or three 32-bit words).
  static_assert(sizeof(detail::EdgeIdx) == sizeof(family.edges()[0]));
  static_assert(sizeof(detail::EdgeTris) == sizeof(r.edge_triangles[0]));
  static_assert(sizeof(detail::TriIdx) == sizeof(family.triangles()[0]));
  const detail::PersistenceIn in{static_cast<uint32_t>(family.points().size()),
                                 static_cast<uint32_t>(family.edges().size()),
                                 static_cast<uint32_t>(family.triangles().size()),
                                 reinterpret_cast<const detail::EdgeIdx*>(family.edges().data()),
                                 reinterpret_cast<const detail::EdgeTris*>(r.edge_triangles.data()),
                                 reinterpret_cast<const detail::TriIdx*>(family.triangles().data()),
                                 r.edge_rho_rank.data(),
                                 r.edge_mu_low.data(),
                                 r.tri_rank.data(),
                                 family.representative().data(),
                                 family.hidden_flags().empty() ? nullptr : family.hidden_flags().data()};
  detail::PersistenceOut out;
  GALPHA_RETURN_IF_ERROR(
      detail::RunEngine(absl::StrCat("computing the persistence diagram of ", family.points().size(), " points"), [&] {
        if (backend == Backend::kCuda) {
          detail::PersistenceOnCuda(in, options.host_finish, options.cuda_stream, &out);
        } else {
          detail::PersistenceOnCpu(in, options.host_finish, &out);
        }
      }));
  if (report != nullptr) *report = std::move(out.report);
  return detail::TakeDiagram(&out);
}

absl::StatusOr<PersistenceDiagram> PersistenceDiagramOf(const AlphaFamily& family,
                                                        absl::Span<const uint32_t> edge_order,
                                                        absl::Span<const uint32_t> triangle_order) {
  if (const PersistenceDiagram* built = family.persistence(); built != nullptr) return *built;
  if (family.report().backend == BackendName(Backend::kCuda) && CudaBackendAvailable()) {
    PersistenceOptions options;
    options.backend = Backend::kCuda;
    absl::StatusOr<PersistenceDiagram> on_device = ComputePersistenceOnBackend(family, options);
    // A device short of memory (a server's builds hold it) leaves the diagram to the host, which
    // computes the same one.
    if (on_device.ok() || !absl::IsResourceExhausted(on_device.status())) return on_device;
  }
  if (edge_order.empty() && !family.edges().empty()) return ComputePersistence(family);
  return ComputePersistence(family, edge_order, triangle_order);
}

}  // namespace galpha
